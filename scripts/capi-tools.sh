#!/usr/bin/env bash
# Installs the pinned C-ABI tools: cbindgen (generates crates/umbrage-capi/include/umbrage/umbrage.h)
# and cargo-c (`cargo cinstall`: header, libumbrage.so with its soname, libumbrage.a, umbrage.pc).
# Skips each tool whose pinned version is already on PATH. Debian bookworm's cargo-c 0.9.14 cannot
# read a version-4 Cargo.lock, so both come from crates.io, built with --locked.
# Usage: scripts/capi-tools.sh            (CARGO_BUILD_JOBS is honoured, e.g. 1 on a busy machine)
set -euo pipefail

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
    cargo install cbindgen --locked --version "=$CBINDGEN_VERSION"
fi

# cargo-cinstall --version prints "cargo-c 0.10.24+cargo-0.98.0"
if have_version cargo-cinstall "$CARGO_C_VERSION"; then
    echo "capi-tools: cargo-c $CARGO_C_VERSION present"
else
    echo "capi-tools: installing cargo-c $CARGO_C_VERSION (builds cargo itself: many minutes)"
    cargo install cargo-c --locked --version "=$CARGO_C_VERSION"
fi
