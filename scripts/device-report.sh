#!/usr/bin/env bash
# A new Vulkan device's report in one line: `scripts/device-report.sh [OUT]` writes into OUT
# (default device-report/): info.txt and info.json (`umbrage info`), the conformance report
# (`umbrage conform`), and the quick fill-rate vs vertex-rate suite (`umbrage bench --suite
# fill-vertex --quick`: bench.json, bench.csv, bench.md and the plots). Nothing here is
# device-specific: the same command runs unchanged on lavapipe and on a discrete GPU.
set -euo pipefail
out="${1:-device-report}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
cd "$(dirname "$0")/.."
cargo build --release --bin umbrage
bin=target/release/umbrage
"$bin" info > "$out/info.txt" && "$bin" info --json > "$out/info.json" && { "$bin" conform --out "$out/conform" || echo "conform: failures, see $out/conform"; } && "$bin" bench --suite fill-vertex --quick --out "$out/bench" > /dev/null && echo "report in $out: info.txt, conform/, bench/bench.md"
