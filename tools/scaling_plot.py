#!/usr/bin/env python3
"""tools/scaling_plot.py: the log-log scaling plot of docs/performance.md from raytrace_bench
outputs. Reads the `SCALE | ...` lines of the files given, writes one SVG (standard library
only). Points named `sponza` are drawn as separate markers (a real model, not the series).
Usage: tools/scaling_plot.py OUT.svg BENCH_OUTPUT...  (a file named *@COMMIT* marks its points
hollow with that note, for a point measured at another commit)"""
import math
import re
import sys

PANELS = [
    ("setup (CPU ms)", [("ours", "setup_ours", "#c0392b"), ("Embree", "setup_embree", "#2c3e50")]),
    ("BVH + mesh (bytes / triangle)", [("ours", "bpt_ours", "#c0392b"), ("Embree", "bpt_embree", "#2c3e50")]),
    ("primary rays (Mrays / CPU-s)", [("ours", "prim_ours", "#c0392b"), ("rtcIntersect1", "prim_embree", "#2c3e50"),
                                      ("rtcIntersect8", "prim_embree8", "#7f8c8d")]),
    ("shadow rays, no cache (Mrays / CPU-s)", [("ours", "shadow_ours", "#c0392b"), ("rtcOccluded1", "shadow_embree", "#2c3e50"),
                                               ("rtcOccluded8", "shadow_embree8", "#7f8c8d")]),
]


def parse(path):
    rows = []
    for line in open(path):
        if not line.startswith("SCALE |"):
            continue
        f = [x.strip() for x in line.split("|")]
        # "word value" pairs of each field: {"ours": 3.5, "embree": 4.97, "embree8": 5.34, ...}
        pairs = lambda s: {k: float(v) for k, v in re.findall(r"([a-z0-9]+) (\d+(?:\.\d+)?)(?=\s|$)", s)}
        setup, bpt, prim, shadow = pairs(f[3]), pairs(f[4]), pairs(f[5]), pairs(f[6])
        rows.append(dict(name=f[1], tris=int(f[2]), setup_ours=setup["ours"], setup_embree=setup["embree"],
                         bpt_ours=bpt["ours"], bpt_embree=bpt["embree"], prim_ours=prim["ours"],
                         prim_embree=prim["embree"], prim_embree8=prim["embree8"], shadow_ours=shadow["ours"],
                         shadow_embree=shadow["embree"], shadow_embree8=shadow["embree8"], hollow="@" in path))
    return rows


def main():
    out, files = sys.argv[1], sys.argv[2:]
    rows = [r for f in files for r in parse(f)]
    W, H, pw, ph, ml, mt = 980, 760, 380, 260, 80, 60
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>',
           f'<text x="{W/2}" y="24" text-anchor="middle" font-size="15">Ray tracer cost against scene size '
           '(generated terrain; squares: Sponza; log-log)</text>']
    for i, (title, series) in enumerate(PANELS):
        x0 = ml + (i % 2) * (pw + 110)
        y0 = mt + (i // 2) * (ph + 90)
        vals = [r[k] for r in rows for _, k, _ in series if r[k] > 0]
        xs = [r["tris"] for r in rows]
        lx0, lx1 = math.floor(math.log10(min(xs))), math.ceil(math.log10(max(xs)))
        ly0, ly1 = math.floor(math.log10(min(vals)) * 2) / 2, math.ceil(math.log10(max(vals)) * 2) / 2
        if ly1 - ly0 < 1:
            ly0 -= 0.5
            ly1 += 0.5
        X = lambda v: x0 + (math.log10(v) - lx0) / (lx1 - lx0) * pw
        Y = lambda v: y0 + ph - (math.log10(v) - ly0) / (ly1 - ly0) * ph
        svg.append(f'<rect x="{x0}" y="{y0}" width="{pw}" height="{ph}" fill="none" stroke="#999"/>')
        svg.append(f'<text x="{x0 + pw/2}" y="{y0 - 8}" text-anchor="middle" font-size="13">{title}</text>')
        for e in range(lx0, lx1 + 1):
            svg.append(f'<line x1="{X(10**e)}" y1="{y0}" x2="{X(10**e)}" y2="{y0+ph}" stroke="#eee"/>')
            svg.append(f'<text x="{X(10**e)}" y="{y0+ph+16}" text-anchor="middle">10^{e}</text>')
        e = ly0
        while e <= ly1 + 1e-9:
            v = 10 ** e
            label = f"{v:.3g}"
            svg.append(f'<line x1="{x0}" y1="{Y(v)}" x2="{x0+pw}" y2="{Y(v)}" stroke="#eee"/>')
            svg.append(f'<text x="{x0-6}" y="{Y(v)+4}" text-anchor="end">{label}</text>')
            e += 0.5
        svg.append(f'<text x="{x0 + pw/2}" y="{y0+ph+34}" text-anchor="middle">triangles</text>')
        for j, (label, key, color) in enumerate(series):
            pts = sorted((r["tris"], r[key], r["hollow"]) for r in rows if r["name"] != "sponza" and r[key] > 0)
            if len(pts) > 1:
                d = " ".join(f"{X(a):.1f},{Y(b):.1f}" for a, b, _ in pts)
                svg.append(f'<polyline points="{d}" fill="none" stroke="{color}" stroke-width="2"/>')
            for a, b, hollow in pts:
                fill = "white" if hollow else color
                svg.append(f'<circle cx="{X(a):.1f}" cy="{Y(b):.1f}" r="4" fill="{fill}" stroke="{color}" stroke-width="2"/>')
            for r in rows:
                if r["name"] == "sponza" and r[key] > 0:
                    svg.append(f'<rect x="{X(r["tris"])-4:.1f}" y="{Y(r[key])-4:.1f}" width="8" height="8" '
                               f'fill="{color}"/>')
            # Legends top left where the curves rise, bottom left where they fall (ray rates).
            ly = y0 + 14 + 16 * j if i < 2 else y0 + ph - 12 - 16 * (len(series) - 1 - j)
            svg.append(f'<line x1="{x0+10}" y1="{ly}" x2="{x0+30}" y2="{ly}" stroke="{color}" stroke-width="2"/>')
            svg.append(f'<text x="{x0+34}" y="{ly+4}">{label}</text>')
    svg.append(f'<text x="{ml}" y="{H-12}" font-size="11">Hollow circles: measured at another commit (see '
               'docs/performance.md). Shared 2-core machine, other work running: CPU time.</text>')
    svg.append("</svg>")
    open(out, "w").write("\n".join(svg) + "\n")


if __name__ == "__main__":
    main()
