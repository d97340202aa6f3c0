#!/usr/bin/env python3
"""How far apart two kernel grids (`ocular kernels -o`) are, texel by texel: the largest
difference of any kernel texel and of any natural radius. For checking that a change to the
precomputation kept its kernels (the same axes, screen and settings on both sides).

    tools/grid_diff.py A.bin B.bin

Reads the files as src/psf/cache.rs writes them: 8-byte magic, format version, header length,
JSON header, then per (pupil, focus) set its pupil and focus (f64), the radii (f32 × 3 per
object) and the texels (f32 × 3 each), and an 8-byte checksum. Needs numpy.
"""
import json
import struct
import sys

import numpy as np


def load(path):
    with open(path, "rb") as f:
        head = f.read(16)
        if len(head) < 16 or head[:8] != b"OCKGRID\0":
            sys.exit(f"{path}: not an ocular kernel grid")
        hlen = struct.unpack("<I", head[12:16])[0]
        header = json.loads(f.read(hlen))
    sets = len(header["pupils_mm"]) * len(header["focus_d"])
    objects = header["objects"]["count"]
    texels = header["texels_per_set"]
    per_set = 16 + 12 * objects + 12 * texels
    data = np.memmap(path, dtype=np.uint8, mode="r", offset=16 + hlen, shape=(sets * per_set,))
    return header, sets, objects, texels, per_set, data


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a, b = load(sys.argv[1]), load(sys.argv[2])
    if a[1:5] != b[1:5]:
        sys.exit(f"the grids' sizes differ: {a[1:5]} against {b[1:5]}")
    _, sets, objects, texels, per_set, da = a
    db = b[5]
    worst_texel = worst_radius = peak = 0.0
    for s in range(sets):
        base = s * per_set + 16
        ra = da[base:base + 12 * objects].view("<f4")
        rb = db[base:base + 12 * objects].view("<f4")
        worst_radius = max(worst_radius, float(np.max(np.abs(ra - rb))))
        start, end = base + 12 * objects, base + 12 * objects + 12 * texels
        ta = da[start:end].view("<f4")
        tb = db[start:end].view("<f4")
        worst_texel = max(worst_texel, float(np.max(np.abs(ta - tb))))
        peak = max(peak, float(np.max(np.abs(ta))))
    print(f"{sets} sets, {objects} objects, {texels} texels per set")
    print(f"largest texel difference {worst_texel:.3e} (largest texel {peak:.3e}), "
          f"largest radius difference {worst_radius:.3e} px")


if __name__ == "__main__":
    main()
