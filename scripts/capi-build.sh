#!/usr/bin/env bash
# `make capi`: installs the C ABI into target/capi/ with cargo-c (include/umbrage/umbrage.h,
# lib/libumbrage.so with its soname, lib/libumbrage.a, lib/pkgconfig/umbrage.pc), exports the
# built-in scenes the C host reads into target/capi/share/umbrage/scenes/, and builds
# target/capi/bin/umbrage-c-host (C99) and target/capi/bin/umbrage-cpp-host (C++17) against that
# install with pkg-config and the system's cc/c++, not cargo.
#   --sanitize     both hosts with -fsanitize=address,undefined (make capi SANITIZE=1)
#   --features F   cargo features of umbrage-capi (the contract test's build: test-panic)
#   --prefix P     install into P instead of target/capi
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
prefix="$PWD/target/capi"
sanitize=0
features=""
while [ $# -gt 0 ]; do
    case "$1" in
        --sanitize) sanitize=1 ;;
        --features) features="$2"; shift ;;
        --prefix) prefix="$2"; shift ;;
        *) echo "capi-build: unknown argument $1" >&2; exit 2 ;;
    esac
    shift
done
./scripts/capi-tools.sh
cargo_features=()
[ -n "$features" ] && cargo_features=(--features "$features")
# The dev profile (opt-level 2, Cargo.toml), in a target directory of its own: cargo-c builds
# with --target and its own flags, and sharing target/ would rebuild the host-side build
# dependencies of every other build each time.
CARGO_TARGET_DIR="$PWD/target/capi-build" cargo cinstall -p umbrage-capi --profile dev --prefix "$prefix" --libdir lib "${cargo_features[@]}"

# The scenes, in the flat format C reads (`umbrage export-scene`).
mkdir -p "$prefix/share/umbrage/scenes"
umbrage=$(./scripts/umbrage-bin.sh)
for s in default hard/eye_in_volume; do
    mkdir -p "$(dirname "$prefix/share/umbrage/scenes/$s.scene")"
    "$umbrage" export-scene "$s" "$prefix/share/umbrage/scenes/$s.scene"
done

export PKG_CONFIG_PATH="$prefix/lib/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
cflags=$(pkg-config --cflags umbrage)
libs="$(pkg-config --libs umbrage) -Wl,-rpath,$prefix/lib"
vulkan_libs=$(pkg-config --libs vulkan)
extra=()
[ "$sanitize" = 1 ] && extra=(-fsanitize=address,undefined -fno-omit-frame-pointer -g)
warn=(-Wall -Wextra -Wpedantic -Werror -Wno-missing-field-initializers)
mkdir -p "$prefix/bin"
cc -std=c99 -D_POSIX_C_SOURCE=200809L -O2 "${warn[@]}" "${extra[@]}" $cflags \
    examples/c/host.c examples/c/scene.c examples/c/dump.c -o "$prefix/bin/umbrage-c-host" $libs $vulkan_libs -lm
cc -std=c99 -D_POSIX_C_SOURCE=200809L -O2 "${warn[@]}" "${extra[@]}" -c $cflags examples/c/scene.c -o "$prefix/bin/scene.o"
c++ -std=c++17 -O2 "${warn[@]}" -Wold-style-cast "${extra[@]}" $cflags -Iexamples/c \
    examples/c/cpp_host.cpp "$prefix/bin/scene.o" -o "$prefix/bin/umbrage-cpp-host" $libs $vulkan_libs
rm -f "$prefix/bin/scene.o"
echo "capi-build: installed into $prefix; built $prefix/bin/umbrage-c-host and umbrage-cpp-host$([ "$sanitize" = 1 ] && echo ' (ASan, UBSan)')"
