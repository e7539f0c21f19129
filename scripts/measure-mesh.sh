#!/usr/bin/env bash
# The measurements of docs/mesh.md: `mcguire`, `compute` and `mesh` with its task stage's
# cull (`mesh`) and without it (`mesh-notask`, PassToggles::mesh_task off: every meshlet's
# mesh workgroup runs, the path before the task stage), side by side in one run, on
# `default`, `bench/vertex` and a 100k-triangle sphere (scenes/bench/sphere100k.toml), on
# Mesa lavapipe 25.0.7 (the system's 22.3.6 has no mesh shaders). The dev profile
# (opt-level 2): the GPU times are lavapipe's own code either way. Writes
# docs/mesh/bench.{md,json}.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/drivers.sh install 25.0.7 >/dev/null
eval "$(./scripts/drivers.sh env 25.0.7)"
cargo build --quiet --bin umbrage
bin="${CARGO_TARGET_DIR:-target}/debug/umbrage"
out=docs/mesh
mkdir -p "$out"
"$bin" bench --scene default --scene bench/vertex --scene scenes/bench/sphere100k.toml \
  --methods mcguire,compute,mesh --mesh-task on,off --frames 10 --size 960x540 \
  --json "$out/bench.json" --markdown "$out/bench.md"
