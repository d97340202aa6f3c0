#!/usr/bin/env python3
"""The table of variants on a GPU, from a folder that tools/gpu_vs_bound.sh or
tools/gpu_variants.sh wrote.

    tools/gpu_merge_table.py OUT_DIR

One Markdown row per scene, eye and size: kernel evaluations per pixel (and, where the bench
reported them, texture reads per pixel) and the splat's GPU time (every pass but the draw,
`raster`, which is reported apart) per variant folder present (the scripts' headers say what
each ran; `default` first, the others in name order), each variant's splat time over the first
variant's, and the draw. Off-axis rows follow, with their ratio to the on-axis row of the first
variant. Nothing is computed but sums and ratios of the `ocular bench --json` reports.
"""
import glob
import json
import os
import sys

def variants(folder):
    names = sorted(d for d in os.listdir(folder) if os.path.isdir(os.path.join(folder, d)))
    return sorted(names, key=lambda n: (n != "default", n))


def load(folder):
    runs = {}
    for variant in variants(folder):
        for path in glob.glob(os.path.join(folder, variant, "*.json")):
            with open(path) as f:
                r = json.load(f)
            key = (r["scene"], r["eye"], r["width"], r["height"], r.get("field") is not None)
            runs[(variant,) + key] = r
    return runs


def splat_ms(r):
    raster = sum(p["mean_ms"] for p in r["passes"] if p["name"] == "raster")
    return r["total"]["mean_ms"] - raster, raster


def cell(r, what):
    if r is None:
        return "—"
    if what == "evals":
        return f"{r['evaluations_per_pixel']:.0f}"
    if what == "reads":
        reads = r.get("texture_reads_per_pixel")
        return "—" if reads is None else f"{reads:.0f}"
    return f"{splat_ms(r)[0]:.2f}"


def main(folder):
    runs = load(folder)
    device = next((r["device"] for r in runs.values()), "no device")
    present = [v for v in variants(folder) if any(k[0] == v for k in runs)]
    first = present[0]
    names = " / ".join(present)
    others = present[1:]
    print(f"Device: {device}. Splat = GPU time of every pass but the draw (`raster`).\n")
    print(f"| scene | eye | size | evaluations / px: {names} | texture reads / px: {names} | "
          f"splat ms: {names} | " + " | ".join(f"{v} ÷ {first}" for v in others)
          + " | draw ms |")
    print("|---|---|---|---|---|---|" + "---|" * len(others) + "---|")
    keys = sorted({k[1:] for k in runs if not k[5]}, key=lambda k: (k[2] * k[3], k[0], k[1]))
    for scene, eye, w, h, _ in keys:
        rs = {v: runs.get((v, scene, eye, w, h, False)) for v in present}
        ev = " / ".join(cell(rs[v], "evals") for v in present)
        reads = " / ".join(cell(rs[v], "reads") for v in present)
        ms = " / ".join(cell(rs[v], "ms") for v in present)
        base = rs.get(first)
        ratios = " | ".join(
            f"{splat_ms(rs[v])[0] / splat_ms(base)[0]:.2f}×" if rs[v] and base else "—"
            for v in others)
        draw = f"{splat_ms(next(r for r in rs.values() if r))[1]:.2f}"
        print(f"| {scene} | {eye} | {w}×{h} | {ev} | {reads} | {ms} | {ratios} | {draw} |")
    off = sorted(k for k in runs if k[5])
    if off:
        print("\n| off axis | eye | size | splat ms | on-axis default splat ms | ratio |")
        print("|---|---|---|---|---|---|")
        for k in off:
            r = runs[k]
            on = runs.get((first,) + k[1:5] + (False,))
            s = splat_ms(r)[0]
            o = splat_ms(on)[0] if on else None
            ratio = f"{s / o:.2f}×" if o else "—"
            print(f"| {k[1]} | {k[2]} | {k[3]}×{k[4]} | {s:.2f} | "
                  f"{o:.2f} | {ratio} |" if o else f"| {k[1]} | {k[2]} | {k[3]}×{k[4]} | {s:.2f} | — | — |")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
