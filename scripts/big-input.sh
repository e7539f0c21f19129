#!/usr/bin/env bash
# Big inputs (issue 13): writes a closed UV sphere of about 5 million triangles as OBJ text
# (N=1582 rings x 1582 segments) and a scene with it over a floor, then loads, plans and
# renders it, printing the wall time and peak memory of each step (GNU time when installed).
# Usage: scripts/big-input.sh [DIR] [N]  (defaults: target/big, 1582)
set -euo pipefail
dir=${1:-target/big}
n=${2:-1582}
mkdir -p "$dir"
obj="$dir/sphere-$n.obj"
if [ ! -s "$obj" ]; then
  python3 - "$obj" "$n" <<'PY'
import math, sys
path, n = sys.argv[1], int(sys.argv[2])
rings, segs = n, n
with open(path, "w") as f:
    f.write(f"# UV sphere, {rings} rings x {segs} segments, closed (poles are single vertices)\n")
    f.write("v 0 1 0\n")
    for i in range(1, rings):
        t = math.pi * i / rings
        y, r = math.cos(t), math.sin(t)
        for j in range(segs):
            p = 2 * math.pi * j / segs
            f.write(f"v {r*math.cos(p):.7f} {y:.7f} {r*math.sin(p):.7f}\n")
    f.write("v 0 -1 0\n")
    top, bottom = 1, 2 + (rings - 1) * segs
    ring = lambda i, j: 2 + (i - 1) * segs + (j % segs)
    out = []
    for j in range(segs):
        out.append(f"f {top} {ring(1, j + 1)} {ring(1, j)}\n")
    for i in range(1, rings - 1):
        for j in range(segs):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)
            out.append(f"f {a} {b} {c}\nf {a} {c} {d}\n")
        if len(out) > 100000:
            f.write("".join(out)); out = []
    for j in range(segs):
        out.append(f"f {bottom} {ring(rings - 1, j)} {ring(rings - 1, j + 1)}\n")
    f.write("".join(out))
PY
fi
cat > "$dir/big.toml" <<TOML
# About 5 million triangles in one closed caster over a floor (scripts/big-input.sh).
[camera]
eye = [0, 3, 6]
target = [0, 0.5, 0]

[[light]]
kind = "point"
position = [2, 5, 2]

[[mesh]]
shape = "plane"
size = [12, 12]
casts_shadow = false

[[mesh]]
obj = "sphere-$n.obj"
translate = [0, 1.2, 0]
TOML
tris=$(grep -c '^f ' "$obj")
echo "big-input: $obj: $tris triangles, $(du -h "$obj" | cut -f1)"
bin=${UMBRAGE_BIN:-target/release/umbrage}
timed() { if [ -x /usr/bin/time ]; then /usr/bin/time -f "  %e s wall, %M KiB peak RSS" "$@"; else time "$@"; fi; }
echo "big-input: info (load, weld, topology, parts)"
timed "$bin" info --scene "$dir/big.toml" | tail -n 3
echo "big-input: render 640x480 with --stats"
timed "$bin" render --scene "$dir/big.toml" --size 640x480 --out "$dir/big.png" --stats "$dir/big-stats.json"
