#!/usr/bin/env python3
"""The off-axis figure of docs/off-axis.md: point lights across a 90° × 60° frame
(tools/recipes/field_points.toml) through the wide-angle eye, rendered with the on-axis PSF
everywhere (left) and with --off-axis (right). Each panel shows the points of the upper-right
quadrant (h = 0, 14, 28, 42°; v = 27, 13.5, 0°), a window around each, magnified.

Usage: python3 tools/field_figure.py [--bin target/release/ocular] [--out tools/figures/off_axis_points.png]
Standard library only (PNG read and written here).
"""

import argparse
import math
import os
import struct
import subprocess
import sys
import tempfile
import zlib


def read_png(path):
    """8-bit RGB or RGBA, non-interlaced (what ocular writes) -> (width, height, rows of RGB)."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width, height, channels = 8, b"", 0, 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos : pos + 8])
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or color not in (2, 6) or interlace:
                sys.exit(f"{path}: only 8-bit RGB/RGBA, non-interlaced PNGs are read")
            channels = 3 if color == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev, i = [], bytearray(stride), 0
    for _ in range(height):
        f, line = raw[i], bytearray(raw[i + 1 : i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - channels] if x >= channels else 0
            b = prev[x]
            c = prev[x - channels] if x >= channels else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pred) & 255
        prev = line
        rows.append([tuple(line[k : k + 3]) for k in range(0, stride, channels)])
    return width, height, rows


def write_png(path, rows):
    height, width = len(rows), len(rows[0])
    raw = b"".join(b"\x00" + bytes(v for px in row for v in px) for row in rows)

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


H_DEG = [0.0, 14.0, 28.0, 42.0]
V_DEG = [27.0, 13.5, 0.0]
WINDOW = 15  # half side of the window around each point (px)


def windows(rows, scale):
    """A grid of windows around the points of the upper-right quadrant, magnified."""
    h, w = len(rows), len(rows[0])
    f = 0.5 * h / math.tan(math.radians(30.0))
    black = (0, 0, 0)
    out = []
    for v in V_DEG:
        y0 = round(h / 2 - f * math.tan(math.radians(v)))
        band = [[] for _ in range((2 * WINDOW + 1) * scale)]
        for k, hd in enumerate(H_DEG):
            x0 = round(w / 2 + f * math.tan(math.radians(hd)))
            for j in range(2 * WINDOW + 1):
                y = y0 - WINDOW + j
                line = []
                for i in range(2 * WINDOW + 1):
                    x = x0 - WINDOW + i
                    px = rows[y][x] if 0 <= y < h and 0 <= x < w else black
                    line.extend([px] * scale)
                if k:
                    line = [(60, 60, 60)] * 2 + line
                for r in range(scale):
                    band[j * scale + r].extend(line)
        if out:
            out.extend([[(60, 60, 60)] * len(band[0])] * 2)
        out.extend(band)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/release/ocular")
    ap.add_argument("--out", default="tools/figures/off_axis_points.png")
    ap.add_argument("--exposure", default="-10", help="EV for both panels (the same, so they compare)")
    ap.add_argument("--scale", type=int, default=4)
    args = ap.parse_args()
    panels = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, extra in [("on-axis", []), ("off-axis", ["--off-axis"])]:
            out = os.path.join(tmp, name + ".png")
            cmd = [args.bin, "render", "--scene", "tools/recipes/field_points.toml", "--eye",
                   "navarro-wide", "--exposure", args.exposure, "-o", out] + extra
            print(" ".join(cmd), flush=True)
            subprocess.run(cmd, check=True)
            panels.append(windows(read_png(out)[2], args.scale))
    gap = [(255, 255, 255)] * 8
    rows = [a + gap + b for a, b in zip(*panels)]
    write_png(args.out, rows)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
