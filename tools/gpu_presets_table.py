#!/usr/bin/env python3
"""The tables of tools/gpu_presets.sh's runs, and the GPU bars of issues #47 and #50 read off them.

    tools/gpu_presets_table.py OUT_DIR

Per scene, eye and size: each preset's GPU time split into the draw (raster, resolve, peel)
and the splat (every other pass), its wall time per frame (upload and read-back included) and
its texture reads per pixel; the old engine's total where it ran. Then the two-eye runs. Every
number is read from the `ocular bench --json` reports; only sums, maxima and ratios are computed.
"""
import os
import sys

# the draw's passes, and reading and splitting a report: gpu_vs_old_table.py's
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gpu_vs_old_table import load, split  # noqa: E402

EYES = ["healthy", "myopia", "astigmatism", "keratoconus"]
SIZES = ["1280x720", "1920x1080", "3840x2160"]


def cell(report):
    if report is None:
        return "—"
    draw, splat = split(report)
    return (f"{draw:.2f} + {splat:.2f} = **{draw + splat:.2f}** "
            f"({report['wall_ms_per_frame']['mean_ms']:.1f} wall, "
            f"{report['texture_reads_per_pixel']:.0f} reads/px)")


def total(report):
    return None if report is None else sum(split(report))


def keep(worst, key, value, tag):
    if key not in worst or value > worst[key][0]:
        worst[key] = (value, tag)


def device(folder):
    lines = open(os.path.join(folder, "devices.txt")).read().strip().splitlines()
    used = [d.lstrip("* ").strip() for d in lines if d.startswith("*") and "used by" not in d]
    return used[0] if used else "?"


def main():
    folder = sys.argv[1]
    print(f"device: {device(folder)}\n")
    print("GPU ms per frame, draw + splat = total (wall ms per frame, texture reads per pixel)\n")
    print("| scene | eye | size | fast | balanced | old engine (its default) |")
    print("|---|---|---|---|---|---|")
    worst = {}
    for size in SIZES:
        for scene in ["primitives", "colonnade"]:
            for eye in EYES:
                tag = f"{scene}_{eye}_{size}"
                fast, bal, old = (load(folder, f"{tag}_{w}") for w in ("fast", "balanced", "old"))
                if fast is None and bal is None and old is None:
                    continue
                old_cell = "—" if old is None else f"{total(old):.2f}"
                print(f"| {scene} | {eye} | {size} | {cell(fast)} | {cell(bal)} | {old_cell} |")
                for name, rep in (("fast", fast), ("balanced", bal)):
                    if rep is not None:
                        keep(worst, (name, size), total(rep), tag)
                        keep(worst, ("draw", size), split(rep)[0], tag)
    print("\nOff axis (colonnade, 1280×720): GPU ms, and the ratio to the same preset on axis\n")
    print("| eye | preset | off axis | on axis | ratio |")
    print("|---|---|---|---|---|")
    for eye in ["healthy", "astigmatism"]:
        for q in ["balanced", "fast"]:
            off = load(folder, f"colonnade_{eye}_1280x720_off-axis_{q}")
            on = load(folder, f"colonnade_{eye}_1280x720_{q}")
            if off is None or on is None:
                continue
            print(f"| {eye} | {q} | {total(off):.2f} | {total(on):.2f} | "
                  f"{total(off) / total(on):.2f}× |")
    print("\nTwo eyes, one submission each (`bench --binocular --quality fast`, 1440×1600 per eye)\n")
    print("| scene | eye | one eye GPU ms (draw + splat) | pair GPU ms | pair wall ms | ratio |")
    print("|---|---|---|---|---|---|")
    for name in sorted(f[:-5] for f in os.listdir(folder) if f.startswith("bin_") and f.endswith(".json")):
        rep = load(folder, name)
        b = rep.get("binocular")
        if not b:
            continue
        draw, splat = split(rep)
        print(f"| {rep['scene']} | {rep['eye']} | {draw:.2f} + {splat:.2f} | "
              f"{b['gpu_total']['mean_ms']:.2f} | {b['wall_ms_per_pair']['mean_ms']:.2f} | "
              f"{b['gpu_ratio']:.2f}× |")
    print("\nThe draw with and without its shading (`--draw-unshaded`) and at 2 and 8 samples per "
          "pixel (`--draw-samples`); myopia, `fast`: raster ms\n")
    print("| scene | size | shaded | unshaded | 2 samples | 8 samples |")
    print("|---|---|---|---|---|---|")
    for size in SIZES:
        for scene in ["primitives", "colonnade"]:
            probe = load(folder, f"probe_{scene}_myopia_{size}_fast")
            shaded = load(folder, f"{scene}_myopia_{size}_fast")
            if probe is None or shaded is None:
                continue
            raster = lambda r: next(p["mean_ms"] for p in r["passes"] if p["name"] == "raster")
            by_samples = [load(folder, f"samples{n}_{scene}_myopia_{size}_fast") for n in (2, 8)]
            cells = ["—" if r is None else f"{raster(r):.2f}" for r in by_samples]
            print(f"| {scene} | {size} | {raster(shaded):.2f} | {raster(probe):.2f} | "
                  f"{cells[0]} | {cells[1]} |")
    print("\nWorst case per preset and size (GPU ms, draw included), and the draw's worst\n")
    for (name, size), (t, tag) in sorted(worst.items()):
        print(f"- {name} {size}: {t:.2f} ms ({tag})")


if __name__ == "__main__":
    main()
