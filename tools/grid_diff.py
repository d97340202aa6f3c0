#!/usr/bin/env python3
"""How far apart two kernel grids (`ocular kernels -o`) are, texel by texel: the largest
difference of any kernel texel and of any natural radius. For checking that a change to the
precomputation kept its kernels (the same axes, screen and settings on both sides).

    tools/grid_diff.py A.bin B.bin [--held-only]

Reads the files as src/psf/cache.rs writes them: 8-byte magic, format version, header length,
JSON header, then per (pupil, focus) set its pupil and focus (f64), the radii (f32 × 3 per
object), from version 3 the top level each object distance holds (u32 per object) and only
the blocks up to it (level-major, then object), in version 2 every block; and an 8-byte
checksum. Blocks a version-3 file does not hold are zero. With --held-only, texels that only
one side holds are left out (a version-3 grid against a version-2 one of the same kernels).
Needs numpy.
"""
import json
import struct
import sys

import numpy as np

FINE_LEVELS, LEVELS_PER_PX, FINE_UNTIL_PX = 8, 4, 2


def level_count(r):
    return r * LEVELS_PER_PX + 1 if r <= FINE_UNTIL_PX else FINE_LEVELS + (r - FINE_UNTIL_PX) + 1


def block_side(level):
    radius = level / LEVELS_PER_PX if level <= FINE_LEVELS else FINE_UNTIL_PX + level - FINE_LEVELS
    return 2 * int(np.ceil(radius)) + 1


def load(path):
    """Yields (radii, texels as (N, 3) float32 in texture order, held mask per texel)."""
    f = open(path, "rb")
    head = f.read(16)
    if len(head) < 16 or head[:8] != b"OCKGRID\0":
        sys.exit(f"{path}: not an ocular kernel grid")
    version, hlen = struct.unpack("<II", head[8:16])
    header = json.loads(f.read(hlen))
    sets = len(header["pupils_mm"]) * len(header["focus_d"])
    no = header["objects"]["count"]
    levels = level_count(header["max_radius_px"])
    sides = [block_side(l) for l in range(levels)]
    starts = np.cumsum([0] + [no * s * s for s in sides])
    texels = header["texels_per_set"]

    def sets_iter():
        for _ in range(sets):
            f.read(16)
            radii = np.frombuffer(f.read(12 * no), "<f4")
            out = np.zeros((texels, 3), np.float32)
            held = np.zeros(texels, bool)
            if version >= 3:
                tops = np.frombuffer(f.read(4 * no), "<u4")
                for level in range(levels):
                    n = sides[level] ** 2
                    for o in np.nonzero(tops >= level)[0]:
                        start = starts[level] + o * n
                        out[start:start + n] = np.frombuffer(f.read(12 * n), "<f4").reshape(n, 3)
                        held[start:start + n] = True
            else:
                out[:] = np.frombuffer(f.read(12 * texels), "<f4").reshape(texels, 3)
                held[:] = True
            yield radii, out, held

    return (sets, no, texels), sets_iter()


def main():
    args = [a for a in sys.argv[1:] if a != "--held-only"]
    held_only = "--held-only" in sys.argv[1:]
    if len(args) != 2:
        sys.exit(__doc__)
    (shape_a, a), (shape_b, b) = load(args[0]), load(args[1])
    if shape_a != shape_b:
        sys.exit(f"the grids' sizes differ: {shape_a} against {shape_b}")
    worst_texel = worst_radius = peak = 0.0
    held = [0, 0]
    for (ra, ta, ha), (rb, tb, hb) in zip(a, b):
        worst_radius = max(worst_radius, float(np.max(np.abs(ra - rb))))
        both = ha & hb if held_only else np.ones(len(ha), bool)
        worst_texel = max(worst_texel, float(np.max(np.abs(ta[both] - tb[both]))))
        peak = max(peak, float(np.max(np.abs(ta))))
        held[0] += int(ha.sum())
        held[1] += int(hb.sum())
    sets, objects, texels = shape_a
    print(f"{sets} sets, {objects} objects, {texels} texels per set; held {held[0]} and "
          f"{held[1]} of {sets * texels}")
    print(f"largest texel difference {worst_texel:.3e} (largest texel {peak:.3e}), "
          f"largest radius difference {worst_radius:.3e} px")


if __name__ == "__main__":
    main()
