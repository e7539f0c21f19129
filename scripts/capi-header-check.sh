#!/usr/bin/env bash
# Regenerates crates/umbrage-capi/include/umbrage/umbrage.h with the pinned cbindgen and fails
# on any difference from the committed header (header drift: resvg's error codes off by one).
# `--write` rewrites the committed header instead. Then compiles the header as C99, C11, C17,
# C++11, C++17 and C++20 with gcc and clang (where installed), -Wall -Wextra -Wpedantic
# -Werror (C++ adds -Wold-style-cast): its static assertions pin the layouts and enum values.
set -euo pipefail
cd "$(dirname "$0")/.."
CBINDGEN_VERSION=0.29.4
crate=crates/umbrage-capi
header=$crate/include/umbrage/umbrage.h
if ! cbindgen --version 2>/dev/null | grep -qF "$CBINDGEN_VERSION"; then
    echo "capi-header-check: cbindgen $CBINDGEN_VERSION is needed (scripts/capi-tools.sh installs it)" >&2
    exit 1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
(cd "$crate" && cbindgen --quiet --config cbindgen.toml --crate umbrage-capi --output "$tmp/umbrage.h")
if [ "${1:-}" = "--write" ]; then
    cp "$tmp/umbrage.h" "$header"
    echo "capi-header-check: wrote $header"
elif ! diff -u "$header" "$tmp/umbrage.h"; then
    echo "capi-header-check: $header differs from what cbindgen $CBINDGEN_VERSION generates: run scripts/capi-header-check.sh --write and commit it" >&2
    exit 1
fi
printf '#include <umbrage/umbrage.h>\nint main(void) { return UMBRAGE_SUCCESS; }\n' > "$tmp/h.c"
cp "$tmp/h.c" "$tmp/h.cpp"
n=0
for cc in gcc clang; do
    command -v "$cc" >/dev/null || { [ -z "${CI:-}" ] || { echo "capi-header-check: $cc is missing under CI (scripts/deps.sh --tests installs it)" >&2; exit 1; }; echo "capi-header-check: $cc not installed, skipped"; continue; }
    for std in c99 c11 c17; do
        "$cc" -std=$std -Wall -Wextra -Wpedantic -Werror -I"$crate/include" -c "$tmp/h.c" -o "$tmp/h.o"
        n=$((n + 1))
    done
done
for cxx in g++ clang++; do
    command -v "$cxx" >/dev/null || { [ -z "${CI:-}" ] || { echo "capi-header-check: $cxx is missing under CI (scripts/deps.sh --tests installs it)" >&2; exit 1; }; echo "capi-header-check: $cxx not installed, skipped"; continue; }
    for std in c++11 c++17 c++20; do
        "$cxx" -std=$std -Wall -Wextra -Wpedantic -Werror -Wold-style-cast -I"$crate/include" -c "$tmp/h.cpp" -o "$tmp/h.o"
        n=$((n + 1))
    done
done
echo "capi-header-check: header up to date; compiled in $n language/compiler configurations"
