#!/usr/bin/env python3
"""tools/make_leaf_texture.py: writes scenes/foliage/leaf.png, the alpha texture of the foliage
scene's leaf cards: a 64x64 RGBA PNG, green, alpha 255 inside a pointed leaf outline with a stem
and two slits along the midrib (thin cut-outs that stress light leaks), 0 elsewhere.
Usage: tools/make_leaf_texture.py [OUT.png]   (only the standard library: zlib and struct)"""
import math
import struct
import sys
import zlib

N = 64


def inside(x, y):
    # (u, v) in [-1, 1]^2, v along the leaf (tip at v = -1, stem at v = +1).
    u = 2.0 * (x + 0.5) / N - 1.0
    v = 2.0 * (y + 0.5) / N - 1.0
    if v > 0.75:  # the stem: a strip 3 texels wide
        return abs(u) < 1.5 / N * 2.0 and v < 0.98
    t = (v + 1.0) / 1.75  # 0 at the tip, 1 at the base
    half = 0.85 * math.sin(math.pi * min(max(t, 0.0), 1.0)) ** 0.8
    if abs(u) >= half:
        return False
    # two slits, one texel wide, beside the midrib
    for cv in (-0.2, 0.3):
        if abs(v - cv) < 0.25 and abs(abs(u) - 0.3) < 1.0 / N * 2.0:
            return False
    return True


def png(rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", N, N, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/foliage/leaf.png"
    rows = []
    for y in range(N):
        row = []
        for x in range(N):
            row += [40, 120, 30, 255] if inside(x, y) else [0, 0, 0, 0]
        rows.append(row)
    with open(out, "wb") as f:
        f.write(png(rows))


if __name__ == "__main__":
    main()
