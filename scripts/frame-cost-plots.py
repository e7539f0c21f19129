#!/usr/bin/env python3
"""Draws docs/frame-cost's curves (SVG, no dependencies) from docs/frame-cost/results.md, the
output of `examples/frame_cost.rs` (see docs/frame-cost/example.md for the runs)."""
import math
import os
import re

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "frame-cost")


def sections(path):
    out, cur = {}, None
    for line in open(path):
        if line.startswith("## "):
            cur = line[3:].strip()
            out[cur] = []
        elif cur and line.startswith("| ") and not line.startswith("| motion"):
            out[cur].append([c.strip() for c in line.strip().strip("|").split("|")])
    return out


def svg(name, title, xlabel, series, xs_label):
    w, h, l, r, t, b = 560, 360, 70, 20, 40, 50
    pts = [p for _, s in series for p in s]
    x0, x1 = min(p[0] for p in pts), max(p[0] for p in pts)
    y0, y1 = min(p[1] for p in pts), max(p[1] for p in pts)
    lx0, lx1 = math.log10(x0), math.log10(x1)
    ly0, ly1 = math.floor(math.log10(y0)), math.ceil(math.log10(y1))
    X = lambda v: l + (math.log10(v) - lx0) / max(lx1 - lx0, 1e-9) * (w - l - r)
    Y = lambda v: h - b - (math.log10(v) - ly0) / max(ly1 - ly0, 1e-9) * (h - t - b)
    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
         f'<rect width="{w}" height="{h}" fill="white"/>',
         f'<text x="{w/2}" y="20" text-anchor="middle" font-size="14">{title}</text>']
    for e in range(ly0, ly1 + 1):
        y = Y(10 ** e)
        o.append(f'<line x1="{l}" x2="{w-r}" y1="{y}" y2="{y}" stroke="#ddd"/>')
        o.append(f'<text x="{l-6}" y="{y+4}" text-anchor="end">{10**e:g} ms</text>')
    for x, lab in xs_label:
        o.append(f'<line x1="{X(x)}" x2="{X(x)}" y1="{t}" y2="{h-b}" stroke="#eee"/>')
        o.append(f'<text x="{X(x)}" y="{h-b+16}" text-anchor="middle">{lab}</text>')
    o.append(f'<text x="{(l+w-r)/2}" y="{h-10}" text-anchor="middle">{xlabel}</text>')
    colours = ["#c0392b", "#2471a3"]
    for i, (label, s) in enumerate(series):
        c = colours[i % len(colours)]
        path = " ".join(f"{'M' if j == 0 else 'L'}{X(x):.1f},{Y(y):.1f}" for j, (x, y) in enumerate(s))
        o.append(f'<path d="{path}" fill="none" stroke="{c}" stroke-width="2"/>')
        for x, y in s:
            o.append(f'<circle cx="{X(x):.1f}" cy="{Y(y):.1f}" r="3" fill="{c}"/>')
        o.append(f'<text x="{l+10}" y="{t+16+16*i}" fill="{c}">{label}</text>')
    o.append("</svg>")
    open(os.path.join(HERE, name), "w").write("\n".join(o))


def main():
    s = sections(os.path.join(HERE, "results.md"))
    def curve(prefix, xkey):
        off, on, labels = [], [], []
        for k, rows in s.items():
            m = re.match(prefix + r" (\d+)", k)
            if not m:
                continue
            n = int(m.group(1))
            for row in rows:
                if row[1] == "keep off":
                    off.append((xkey(n, row), float(row[2])))
                elif row[1].startswith("keep on"):
                    on.append((xkey(n, row), float(row[2])))
        off.sort(); on.sort()
        return off, on
    off, on = curve("lights", lambda n, row: n)
    svg("example-lights.svg", "bench/vertex, camera orbiting: CPU per frame against lights", "lights (36 casters)",
        [("planned every frame (keep off)", off), ("kept (keep on)", on)], [(x, str(x)) for x, _ in off])
    off, on = curve("rooms", lambda n, row: 17 * n * n)
    svg("example-casters.svg", "level, camera walking: CPU per frame against casters", "casters (2 bounded lights a room)",
        [("planned every frame (keep off)", off), ("kept (keep on)", on)], [(x, str(x)) for x, _ in off])


if __name__ == "__main__":
    main()
