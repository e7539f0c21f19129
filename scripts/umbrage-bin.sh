#!/usr/bin/env bash
# Prints the path of target/debug/umbrage (or $CARGO_TARGET_DIR's), building it only when it is
# missing or older than a file it is built from (src/, shaders/, crates/, build.rs, Cargo.toml,
# Cargo.lock). The scripts that run the CLI call this instead of `cargo build --bin umbrage`:
# in `make test` the workspace's `cargo test --all-targets` has just built it, with the
# features the workspace's tests unify, and `cargo build --bin umbrage` would compile the CLI and
# the crates under it once more for the CLI's own feature set (minutes on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
bin="${CARGO_TARGET_DIR:-$PWD/target}/debug/umbrage"
case "$bin" in /*) ;; *) bin="$PWD/$bin" ;; esac
if [ ! -x "$bin" ] || [ -n "$(find src shaders crates build.rs Cargo.toml Cargo.lock -type f -newer "$bin" -print -quit)" ]; then
    cargo build --quiet -p umbrage-cli --bin umbrage >&2
fi
echo "$bin"
