#!/usr/bin/env python3
"""Flat-shaded PNG views of triangle meshes (OBJ), side by side: the figures of docs/results.md.

Standard library only (zlib, struct). Usage:
    render.py OUT.png "Title 1" MESH1.obj "Title 2" MESH2.obj ...
Every mesh is drawn from the same direction (turned 35 degrees about z, tilted 25 degrees),
scaled to its panel, back faces culled, painter's order, Lambert shading from a light above the
viewer's left; every triangle's edges are darkened so that the tessellation shows. Titles are
not drawn (no font); docs/results.md names the panels left to right.
"""
import math
import struct
import sys
import zlib

SIZE = 320  # panel side in pixels
SS = 2  # supersampling per axis


def load(path):
    vs, fs = [], []
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                vs.append(tuple(float(x) for x in t[1:4]))
            elif t[0] == "f":
                fs.append([int(x.split("/")[0]) - 1 for x in t[1:]])
    return vs, fs


def view(p):
    a, b = math.radians(35), math.radians(25)
    x, y, z = p
    x, y = x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)
    y, z = y * math.cos(b) - z * math.sin(b), y * math.sin(b) + z * math.cos(b)
    return x, y, z  # screen x to the right, z up, y into the screen


def draw(image, width, vs, fs, ox):
    pts = [view(p) for p in vs]
    xs, zs = [p[0] for p in pts], [p[2] for p in pts]
    side = SIZE * SS
    scale = 0.92 * side / max(max(xs) - min(xs), max(zs) - min(zs))
    cx, cz = (max(xs) + min(xs)) / 2, (max(zs) + min(zs)) / 2
    light = (-0.4, -0.6, 0.7)
    n0 = math.sqrt(sum(c * c for c in light))
    light = tuple(c / n0 for c in light)
    tris = []
    for f in fs:
        for i in range(1, len(f) - 1):
            a, b, c = pts[f[0]], pts[f[i]], pts[f[i + 1]]
            u = tuple(q - p for p, q in zip(a, b))
            v = tuple(q - p for p, q in zip(a, c))
            n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
            length = math.sqrt(sum(x * x for x in n)) or 1.0
            n = tuple(x / length for x in n)
            if n[1] >= 0:  # facing away: the viewer looks along +y
                continue
            shade = 0.25 + 0.75 * max(0.0, sum(x * y for x, y in zip(n, light)))
            screen = [(ox * SS + side / 2 + (p[0] - cx) * scale, side / 2 - (p[2] - cz) * scale) for p in (a, b, c)]
            tris.append(((a[1] + b[1] + c[1]) / 3, shade, screen))
    tris.sort(key=lambda t: -t[0])
    for _, shade, ((x0, y0), (x1, y1), (x2, y2)) in tris:
        area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if area == 0:
            continue
        g = 255 * shade
        fill = (int(g * 0.85), int(g * 0.9), int(g))
        edge = tuple(int(c * 0.55) for c in fill)
        # Edge width in barycentric terms: about one supersampled pixel.
        heights = [abs(area) / math.hypot(x2 - x1, y2 - y1), abs(area) / math.hypot(x0 - x2, y0 - y2),
                   abs(area) / math.hypot(x1 - x0, y1 - y0)]
        for py in range(max(0, int(min(y0, y1, y2))), min(side, int(max(y0, y1, y2)) + 1)):
            for px in range(max(0, int(min(x0, x1, x2))), min(width * SS, int(max(x0, x1, x2)) + 1)):
                x, y = px + 0.5, py + 0.5
                w0 = ((x1 - x) * (y2 - y) - (x2 - x) * (y1 - y)) / area
                w1 = ((x2 - x) * (y0 - y) - (x0 - x) * (y2 - y)) / area
                w2 = 1 - w0 - w1
                if min(w0, w1, w2) < 0:
                    continue
                near = min(w0 * heights[0], w1 * heights[1], w2 * heights[2]) < 0.9
                image[py][px] = edge if near else fill


def main():
    out_path, pairs = sys.argv[1], sys.argv[2:]
    panels = len(pairs) // 2
    width = SIZE * panels
    image = [[(255, 255, 255)] * (width * SS) for _ in range(SIZE * SS)]
    for k in range(panels):
        vs, fs = load(pairs[2 * k + 1])
        draw(image, width, vs, fs, k * SIZE)
    rows = []
    for y in range(SIZE):
        row = bytearray([0])
        for x in range(width):
            acc = [0, 0, 0]
            for dy in range(SS):
                for dx in range(SS):
                    p = image[y * SS + dy][x * SS + dx]
                    for c in range(3):
                        acc[c] += p[c]
            row.extend(a // (SS * SS) for a in acc)
        rows.append(bytes(row))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, SIZE, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(b"".join(rows), 9)) + chunk(b"IEND", b"")
    with open(out_path, "wb") as f:
        f.write(png)


if __name__ == "__main__":
    main()
