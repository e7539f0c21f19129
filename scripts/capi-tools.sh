#!/usr/bin/env bash
# Installs the pinned C-ABI tools: cbindgen (generates crates/umbrage-capi/include/umbrage/umbrage.h)
# and cargo-c (`cargo cinstall`: header, libumbrage.so with its soname, libumbrage.a, umbrage.pc).
# Skips each tool whose pinned version is already on PATH. Debian bookworm's cargo-c 0.9.14 cannot
# read a version-4 Cargo.lock, so both come from crates.io, built with --locked, and --debug: a
# tool run a few times a CI run needs no optimisation, and the unoptimised build of cargo-c (the
# cargo library, hundreds of crates) costs a fresh CI machine less CPU.
# Usage: scripts/capi-tools.sh            (CARGO_BUILD_JOBS is honoured, e.g. 1 on a busy machine)
set -euo pipefail
# One install at a time: .ci/run starts this in the background while `make test` may call it
# too; the second waits here, then finds the tools present.
mkdir -p "${CARGO_HOME:-$HOME/.cargo}"
exec 9>"${CARGO_HOME:-$HOME/.cargo}/.umbrage-capi-tools.lock"
flock 9

CBINDGEN_VERSION=0.29.4
# the cargo-c release built on cargo 0.98, whose rust-version (1.95) is the toolchain's
CARGO_C_VERSION=0.10.24

have_version() { # tool, version: does `tool --version` print it?
    command -v "$1" >/dev/null 2>&1 && "$1" --version 2>/dev/null | grep -qF "$2"
}

if have_version cbindgen "$CBINDGEN_VERSION"; then
    echo "capi-tools: cbindgen $CBINDGEN_VERSION present"
else
    echo "capi-tools: installing cbindgen $CBINDGEN_VERSION"
    cargo install cbindgen --locked --debug --version "=$CBINDGEN_VERSION"
fi

# cargo-cinstall --version prints "cargo-c 0.10.24+cargo-0.98.0"
if have_version cargo-cinstall "$CARGO_C_VERSION"; then
    echo "capi-tools: cargo-c $CARGO_C_VERSION present"
else
    echo "capi-tools: installing cargo-c $CARGO_C_VERSION (builds cargo itself: many minutes)"
    cargo install cargo-c --locked --debug --version "=$CARGO_C_VERSION"
fi
