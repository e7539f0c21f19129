#!/usr/bin/env bash
# The measurements of docs/raytrace.md, on Mesa lavapipe 25.0.7 (ray query), in one run:
# rayquery / mcguire / shadowmap side by side on the bench scenes (and the city asset when
# scripts/fetch-assets.sh could get it), the resolution sweep, area lights at 1/4/16/64
# samples, four spheres from 16k to 1M triangles, and the quick fill-vertex suite (whose technique list includes rayquery there).
# Writes docs/raytrace/*.md and *.json. Usage: scripts/measure-raytrace.sh [--no-suite]
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/drivers.sh install 25.0.7 >/dev/null
eval "$(./scripts/drivers.sh env 25.0.7)"
cargo build --release --quiet
bin=target/release/umbrage
out=docs/raytrace
mkdir -p "$out"
methods=rayquery,mcguire,shadowmap

scenes=(--scene default --scene bench/fill --scene bench/vertex)
./scripts/fetch-assets.sh || true
if [ -f target/assets/buildings.obj ]; then
  # The OpenFOAM city block (z-up, rotated y-up) with a street light among the buildings, as
  # tests/engine/parts.rs sets it up.
  cat > target/assets/city.toml <<EOF
[camera]
eye = [120.0, 260.0, 60.0]
target = [120.0, 0.0, -90.0]
[[light]]
kind = "point"
position = [120.0, 12.0, -95.0]
[[light]]
kind = "directional"
direction = [-0.3, -1.0, -0.45]
intensity = 0.6
[[mesh]]
shape = "plane"
size = [400.0, 400.0]
translate = [120.0, 0.0, -90.0]
casts_shadow = false
[[mesh]]
name = "city"
obj = "buildings.obj"
rotate_deg = [-90.0, 0.0, 0.0]
EOF
  scenes+=(--scene target/assets/city.toml)
fi
"$bin" bench "${scenes[@]}" --methods "$methods" --frames 10 --json "$out/scenes.json" --markdown "$out/scenes.md"

# Resolution: a ray per pixel grows with pixels; the volumes' cost with their fill.
: > "$out/resolution.md"
for size in 480x270 960x540 1920x1080; do
  "$bin" bench --scene default --scene bench/fill --methods rayquery,mcguire --size "$size" --frames 8 \
    --json "$out/resolution-$size.json" --markdown /tmp/umbrage-res.md
  { echo "### $size"; echo; sed -n '/^| scene/,$p' /tmp/umbrage-res.md; echo; } >> "$out/resolution.md"
done

# Triangles, up to 1M: four tessellated spheres over a floor, one point light; each
# technique's cost against the casters' triangle count (the BLAS build is once per scene).
: > "$out/triangles.md"
for spec in 64:33 256:126 500:251; do
  seg=${spec%%:*}; rings=${spec##*:}
  toml="target/tess-$seg.toml"
  {
    printf '[camera]\neye = [0.0, 9.0, 12.0]\ntarget = [0.0, 0.0, 0.0]\n'
    printf '[[light]]\nkind = "point"\nposition = [2.0, 12.0, 3.0]\n'
    printf '[[mesh]]\nshape = "plane"\nsize = [40.0, 40.0]\ncasts_shadow = false\n'
    for x in -3 3; do for z in -3 3; do
      printf '[[mesh]]\nshape = "sphere"\nradius = 1.2\nsegments = %d\nrings = %d\ntranslate = [%s.0, 1.5, %s.0]\n' "$seg" "$rings" "$x" "$z"
    done; done
  } > "$toml"
  "$bin" bench --scene "$toml" --methods rayquery,mcguire,shadowmap --shadow-map-size 2048 --frames 6 \
    --json "$out/triangles-$seg.json" --markdown /tmp/umbrage-tess.md
  { echo "### 4 spheres of $seg x $rings"; echo; sed -n '/^| scene/,$p' /tmp/umbrage-tess.md; echo; } >> "$out/triangles.md"
done

# Area lights: N point-light samples, each one determination pass (volumes) or one ray a
# pixel (rayquery).
: > "$out/area.md"
for n in 1 4 16 64; do
  sed "s/^samples = .*/samples = $n/" scenes/area/disc.toml > "target/area-disc-$n.toml"
  "$bin" bench --scene "target/area-disc-$n.toml" --methods rayquery,mcguire --frames 6 \
    --json "$out/area-$n.json" --markdown /tmp/umbrage-area.md
  { echo "### $n samples"; echo; sed -n '/^| scene/,$p' /tmp/umbrage-area.md; echo; } >> "$out/area.md"
done

if [ "${1:-}" != "--no-suite" ]; then
  "$bin" bench --suite fill-vertex --quick --out "$out/suite"
fi
