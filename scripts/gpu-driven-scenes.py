#!/usr/bin/env python3
"""The scenes of docs/gpu-driven.md: 256 UV spheres of 512 triangles over a floor, as 256
casters (casters256.toml) and merged into one OBJ caster (merged256.toml + merged256.obj: the
same triangles), the same triangles grouped into 4, 16 and 64 OBJ casters (casters4.toml ..
casters64.toml: the casters sweep at fixed triangles, fixed coverage), and one
490,000-triangle sphere (big.toml).

    scripts/gpu-driven-scenes.py target/gpu-driven
    umbrage bench --scene target/gpu-driven/casters256.toml --scene target/gpu-driven/merged256.toml \\
        --scene target/gpu-driven/big.toml --methods mcguire,compute,edgequad --frames 7
"""
import math
import os
import sys

HEADER = """[camera]
eye = [0.0, 14.0, 22.0]
target = [0.0, 0.0, 0.0]

[[light]]
kind = "point"
position = [0.5, 10.0, 0.3]

[[mesh]]
name = "floor"
shape = "plane"
casts_shadow = false
size = [60.0, 60.0]
"""


def centres():
    side = 16
    return [((k % side - side / 2) * 1.5, 1.0, (k // side - side / 2) * 1.5) for k in range(256)]


def uv_sphere(c, r, seg, rings, vs, fs):
    """umbrage's shapes::sphere layout: a pole, rings - 1 rings of seg vertices, a pole."""
    top = len(vs)
    vs.append((c[0], c[1] + r, c[2]))
    for i in range(1, rings):
        th = math.pi * i / rings
        for j in range(seg):
            ph = 2 * math.pi * j / seg
            vs.append((c[0] + r * math.sin(th) * math.cos(ph), c[1] + r * math.cos(th), c[2] + r * math.sin(th) * math.sin(ph)))
    bot = len(vs)
    vs.append((c[0], c[1] - r, c[2]))

    def ring(i, j):
        return top + 1 + (i - 1) * seg + (j % seg)

    for j in range(seg):
        fs.append((top, ring(1, j + 1), ring(1, j)))
    for i in range(1, rings - 1):
        for j in range(seg):
            a, b, cc, d = ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)
            fs.append((a, b, cc))
            fs.append((a, cc, d))
    for j in range(seg):
        fs.append((bot, ring(rings - 1, j), ring(rings - 1, j + 1)))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "target/gpu-driven"
    os.makedirs(out, exist_ok=True)
    s = ['name = "casters256"', HEADER]
    for k, (x, y, z) in enumerate(centres()):
        s += ["[[mesh]]", f'name = "s{k}"', 'shape = "sphere"', "radius = 0.5", "segments = 32", "rings = 9", f"translate = [{x:g}, {y:g}, {z:g}]", ""]
    open(os.path.join(out, "casters256.toml"), "w").write("\n".join(s))
    vs, fs = [], []
    for c in centres():
        uv_sphere(c, 0.5, 32, 9, vs, fs)
    with open(os.path.join(out, "merged256.obj"), "w") as f:
        f.writelines(f"v {v[0]:g} {v[1]:g} {v[2]:g}\n" for v in vs)
        f.writelines(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n" for t in fs)
    open(os.path.join(out, "merged256.toml"), "w").write('name = "merged256"\n' + HEADER + '\n[[mesh]]\nname = "spheres"\nobj = "merged256.obj"\n')
    # The casters sweep: the 256 spheres in n groups of 256 / n, one OBJ caster a group.
    for n in (4, 16, 64):
        per = 256 // n
        toml = [f'name = "casters{n}"', HEADER]
        for g in range(n):
            gv, gf = [], []
            for c in centres()[g * per:(g + 1) * per]:
                uv_sphere(c, 0.5, 32, 9, gv, gf)
            name = f"casters{n}_{g}.obj"
            with open(os.path.join(out, name), "w") as f:
                f.writelines(f"v {v[0]:g} {v[1]:g} {v[2]:g}\n" for v in gv)
                f.writelines(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n" for t in gf)
            toml += ["[[mesh]]", f'name = "g{g}"', f'obj = "{name}"', ""]
        open(os.path.join(out, f"casters{n}.toml"), "w").write("\n".join(toml))
    big = HEADER.replace("[0.0, 14.0, 22.0]", "[0.0, 4.0, 6.0]").replace("[0.5, 10.0, 0.3]", "[0.5, 5.0, 0.3]").replace("[60.0, 60.0]", "[30.0, 30.0]")
    open(os.path.join(out, "big.toml"), "w").write('name = "big"\n' + big + '\n[[mesh]]\nname = "ball"\nshape = "sphere"\nradius = 1.0\nsegments = 700\nrings = 351\ntranslate = [0.0, 1.2, 0.0]\n')
    print(f"{len(fs)} merged triangles; scenes in {out}")


main()
