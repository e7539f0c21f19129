#!/usr/bin/env bash
# The measurements of docs/shadowmap-cube.md: a point light's six shadow-map cube faces as
# tiles of one atlas (a draw per face) against six multiview views of one draw, side by side
# in one run, with McGuire's volumes beside them, at 512 and 2048 texels. On Mesa lavapipe
# 25.0.7: the system's 22.3.6 loses clipped triangles in multiview, and umbrage refuses it
# there (src/gpu/quirks.rs). Writes docs/shadowmap-cube/maps-N.{md,json}.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/drivers.sh install 25.0.7 >/dev/null
eval "$(./scripts/drivers.sh env 25.0.7)"
cargo build --release --quiet
bin=target/release/umbrage
out=docs/shadowmap-cube
mkdir -p "$out"
for size in 512 2048; do
  "$bin" bench --scene default --scene stress --scene cubes --scene bench/fill --scene bench/vertex \
    --methods mcguire,shadowmap --shadow-map-size "$size" --cube atlas,multiview --frames 10 --size 960x540 \
    --json "$out/maps-$size.json" --markdown "$out/maps-$size.md"
done
