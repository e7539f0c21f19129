#!/usr/bin/env bash
# The side-by-side run of docs/gpu-driven.md (issue #37 item 5): `mcguire` (CPU silhouettes),
# `compute` (GPU silhouettes, GPU-written indirect draws) and `mesh` (mesh-shader extrusion) in
# one `umbrage bench` run on Mesa lavapipe 25.0.7 (the one driver here with VK_EXT_mesh_shader),
# round-robin frame by frame: `default`, `bench/vertex`, `bench/fill`, and the casters sweep at
# fixed triangles and coverage (scripts/gpu-driven-scenes.py: 131,072 triangles as 1, 4, 16,
# 64 and 256 casters), plus the 490k-triangle sphere. Writes docs/gpu-driven/run.{md,json}.
#   scripts/measure-gpu-driven.sh [FRAMES]     (default 7)
set -euo pipefail
cd "$(dirname "$0")/.."
frames="${1:-7}"
./scripts/drivers.sh install 25.0.7 >/dev/null
eval "$(./scripts/drivers.sh env 25.0.7)"
cargo build --release --quiet --bin umbrage
bin="${CARGO_TARGET_DIR:-target}/release/umbrage"
scenes=target/gpu-driven
python3 scripts/gpu-driven-scenes.py "$scenes" >/dev/null
out=docs/gpu-driven
mkdir -p "$out"
args=()
for s in default bench/vertex bench/fill "$scenes/merged256.toml" "$scenes/casters4.toml" \
  "$scenes/casters16.toml" "$scenes/casters64.toml" "$scenes/casters256.toml" "$scenes/big.toml"; do
  args+=(--scene "$s")
done
"$bin" bench "${args[@]}" --methods mcguire,compute,mesh --frames "$frames" --size 960x540 \
  --json "$out/run.json" --markdown "$out/run.md"
echo "wrote $out/run.md and $out/run.json ($(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg))"
