#!/usr/bin/env python3
"""tools/scaling_plot.py: the log-log scaling plot of docs/performance.md from raytrace_bench and
raster_bench outputs. Reads the `SCALE | ...` lines (raytrace_bench) and `RSCALE | ...` lines
(raster_bench) of the files given, writes one SVG (standard library only): four ray tracer panels
and two raster panels. Points named `sponza` are drawn as separate markers (a real model, not the
series).
Usage: tools/scaling_plot.py OUT.svg BENCH_OUTPUT...  (a file named *@COMMIT* marks its points
hollow with that note, for a point measured at another commit)"""
import math
import re
import sys

OURS, ANCHOR, ANCHOR2, OURS2 = "#c0392b", "#2c3e50", "#7f8c8d", "#e67e22"
PANELS = [
    ("ray tracer setup (CPU ms)", [("ours", "setup_ours", OURS), ("Embree", "setup_embree", ANCHOR)]),
    ("BVH + mesh (bytes / triangle)", [("ours", "bpt_ours", OURS), ("Embree", "bpt_embree", ANCHOR)]),
    ("primary rays (Mrays / CPU-s)", [("ours", "prim_ours", OURS), ("rtcIntersect1", "prim_embree", ANCHOR),
                                      ("rtcIntersect8", "prim_embree8", ANCHOR2)]),
    ("shadow rays, no cache (Mrays / CPU-s)", [("ours", "shadow_ours", OURS), ("rtcOccluded1", "shadow_embree", ANCHOR),
                                               ("rtcOccluded8", "shadow_embree8", ANCHOR2)]),
    ("raster frame, 1920x1080, 2048² map (CPU ms)", [("ours, all channels", "frame_all", OURS),
                                                    ("ours, float beauty", "frame_beauty", OURS2),
                                                    ("bare lavapipe", "frame_bare", ANCHOR)]),
    ("raster construction: upload (CPU ms)", [("ours", "construct_ours", OURS), ("bare lavapipe", "construct_bare", ANCHOR)]),
]
# Where each panel's legend goes: top left where the curves rise, bottom left where they fall.
LEGEND_TOP = [True, True, False, False, True, True]


def pairs(s):
    """The "word value" pairs of one field: {"ours": 3.5, "embree8": 5.34, "ours_all": 89.5, ...}"""
    return {k: float(v) for k, v in re.findall(r"([a-z0-9_]+) (\d+(?:\.\d+)?)(?=\s|$)", s)}


def parse(path):
    rows = []
    hollow = "@" in path
    for line in open(path):
        f = [x.strip() for x in line.split("|")]
        if line.startswith("SCALE |"):
            setup, bpt, prim, shadow = pairs(f[3]), pairs(f[4]), pairs(f[5]), pairs(f[6])
            rows.append(dict(name=f[1].lower(), tris=int(f[2]), setup_ours=setup["ours"],
                             setup_embree=setup["embree"], bpt_ours=bpt["ours"], bpt_embree=bpt["embree"],
                             prim_ours=prim["ours"], prim_embree=prim["embree"], prim_embree8=prim["embree8"],
                             shadow_ours=shadow["ours"], shadow_embree=shadow["embree"],
                             shadow_embree8=shadow["embree8"], hollow=hollow))
        elif line.startswith("RSCALE |"):
            fields = {k: v for x in f[3:] for k, v in [(x.split(" ")[0], pairs(x))] if x}
            frame, construct = fields["frame_cpu"], fields["construct_cpu"]
            rows.append(dict(name=f[1].lower(), tris=int(f[2]), frame_all=frame["ours_all"],
                             frame_beauty=frame["ours_beauty"], frame_bare=frame["bare"],
                             construct_ours=construct["ours"], construct_bare=construct["bare"], hollow=hollow))
    return rows


def main():
    out, files = sys.argv[1], sys.argv[2:]
    rows = [r for f in files for r in parse(f)]
    pw, ph, ml, mt, gapx, gapy = 380, 260, 80, 60, 110, 90
    W = ml + 2 * pw + gapx + 30
    H = mt + 3 * (ph + gapy) + 20
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>',
           f'<text x="{W/2}" y="24" text-anchor="middle" font-size="15">Cost against scene size '
           '(generated terrain; squares: Sponza; log-log)</text>']
    for i, (title, series) in enumerate(PANELS):
        x0 = ml + (i % 2) * (pw + gapx)
        y0 = mt + (i // 2) * (ph + gapy)
        mine = [r for r in rows if all(k in r for _, k, _ in series)]
        if not mine:
            continue
        vals = [r[k] for r in mine for _, k, _ in series if r[k] > 0]
        xs = [r["tris"] for r in mine]
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
            label = f"{v:.3g}" if v < 1000 else f"{v:,.0f}"
            svg.append(f'<line x1="{x0}" y1="{Y(v)}" x2="{x0+pw}" y2="{Y(v)}" stroke="#eee"/>')
            svg.append(f'<text x="{x0-6}" y="{Y(v)+4}" text-anchor="end">{label}</text>')
            e += 0.5
        svg.append(f'<text x="{x0 + pw/2}" y="{y0+ph+34}" text-anchor="middle">triangles</text>')
        for j, (label, key, color) in enumerate(series):
            pts = sorted((r["tris"], r[key], r["hollow"]) for r in mine if r["name"] != "sponza" and r[key] > 0)
            if len(pts) > 1:
                d = " ".join(f"{X(a):.1f},{Y(b):.1f}" for a, b, _ in pts)
                svg.append(f'<polyline points="{d}" fill="none" stroke="{color}" stroke-width="2"/>')
            for a, b, hollow in pts:
                fill = "white" if hollow else color
                svg.append(f'<circle cx="{X(a):.1f}" cy="{Y(b):.1f}" r="4" fill="{fill}" stroke="{color}" stroke-width="2"/>')
            for r in mine:
                if r["name"] == "sponza" and r[key] > 0:
                    svg.append(f'<rect x="{X(r["tris"])-4:.1f}" y="{Y(r[key])-4:.1f}" width="8" height="8" '
                               f'fill="{color}"/>')
            ly = y0 + 14 + 16 * j if LEGEND_TOP[i] else y0 + ph - 12 - 16 * (len(series) - 1 - j)
            svg.append(f'<line x1="{x0+10}" y1="{ly}" x2="{x0+30}" y2="{ly}" stroke="{color}" stroke-width="2"/>')
            svg.append(f'<text x="{x0+34}" y="{ly+4}">{label}</text>')
    svg.append(f'<text x="{ml}" y="{H-26}" font-size="11">Hollow circles: measured at another commit (see '
               'docs/performance.md). Shared 2-core machine, other work running: CPU time.</text>')
    svg.append(f'<text x="{ml}" y="{H-12}" font-size="11">Raster: lavapipe with LP_NUM_THREADS=2, process CPU time '
               '(lavapipe\'s threads included); the Sponza square is its framed default camera.</text>')
    svg.append("</svg>")
    open(out, "w").write("\n".join(svg) + "\n")


if __name__ == "__main__":
    main()
