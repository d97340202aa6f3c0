#!/usr/bin/env python3
"""The GPU tables of docs/validation.md from a folder that tools/gpu_bench.sh wrote.

    tools/gpu_bench_table.py OUT_DIR

Prints two Markdown tables: the paper's Table 3 layout (every scene, eye and size, this
engine's GPU time per pass group and wall time beside the baseline's), and the off-axis cost
(each `--off-axis` run against the on-axis run of the same scene, eye and size). Every number
is read from the `ocular bench --json` reports; nothing is computed but sums and ratios.
"""
import glob
import json
import os
import sys

PAPER_720P = "11.9–24.5"  # the seed paper's Table 3, TITAN Xp, 1280×720 (docs/validation.md)
SCENES = ["primitives", "colonnade"]
EYES = ["healthy", "myopia", "astigmatism", "keratoconus"]


def load(folder):
    runs = {}
    for path in glob.glob(os.path.join(folder, "*.json")):
        with open(path) as f:
            report = json.load(f)
        off_axis = report.get("field") is not None
        key = (report["scene"], report["eye"], report["width"], report["height"], off_axis)
        runs[key] = report
    return runs


def passes(report):
    return {p["name"]: p["mean_ms"] for p in report["passes"]}


def table3(runs):
    print("| scene | eye | size | Rmax px | list entries | submissions (bands) | GPU ms: total = "
          "raster + sort + convolve + rest | wall ms (p95) | baseline: wall / GPU ms | wall, "
          "baseline ÷ this | paper, TITAN Xp |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    sizes = sorted({(k[2], k[3]) for k in runs if not k[4]})
    for w, h in sizes:
        for scene in SCENES:
            for eye in EYES:
                r = runs.get((scene, eye, w, h, False))
                if r is None:
                    print(f"| {scene} | {eye} | {w}×{h} | — | — | — | not run | — | — | — | — |")
                    continue
                p = passes(r)
                total = r["total"]["mean_ms"]
                raster = p.get("raster", 0.0)
                sort = p.get("tile sort", 0.0)
                conv = p.get("convolve", 0.0)
                rest = total - raster - sort - conv
                wall = r["wall_ms_per_frame"]
                b = r.get("baseline")
                base = (f"{b['wall_ms_per_frame']['mean_ms']:.1f} / {b['gpu_total']['mean_ms']:.1f}"
                        if b else "—")
                ratio = f"{b['speedup']:.2f}×" if b else "—"
                paper = PAPER_720P if (w, h) == (1280, 720) else "—"
                c = r["counters"]
                # reports from before the GPU band plan carry no band count
                bands = f" ({c['bands']})" if "bands" in c else ""
                print(f"| {scene} | {eye} | {w}×{h} | {r['max_radius_px']} "
                      f"| {r['list_entries'] / 1e6:.1f} M | {c['submissions']}{bands} "
                      f"| {total:.1f} = {raster:.1f} + {sort:.1f} + {conv:.1f} + {rest:.1f} "
                      f"| {wall['mean_ms']:.1f} ({wall['p95_ms']:.1f}) | {base} | {ratio} "
                      f"| {paper} |")


def off_axis(runs):
    keys = sorted(k for k in runs if k[4])
    if not keys:
        return
    print()
    print("| scene | eye | size | field nodes | list entries: on / off axis | GPU ms: on axis "
          "| off axis (convolve) | off ÷ on | off-axis precomputation s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for scene, eye, w, h, _ in keys:
        off = runs[(scene, eye, w, h, True)]
        on = runs.get((scene, eye, w, h, False))
        field = off["field"]
        nodes = f"{len(field['h_deg'])} × {len(field['v_deg'])}"
        t_off = off["total"]["mean_ms"]
        conv = passes(off).get("convolve", 0.0)
        pre = off["precompute"]["seconds_total"]
        if on is None:
            print(f"| {scene} | {eye} | {w}×{h} | {nodes} | — / {off['list_entries'] / 1e6:.1f} M "
                  f"| — | {t_off:.1f} ({conv:.1f}) | — | {pre:.1f} |")
            continue
        t_on = on["total"]["mean_ms"]
        print(f"| {scene} | {eye} | {w}×{h} | {nodes} "
              f"| {on['list_entries'] / 1e6:.1f} M / {off['list_entries'] / 1e6:.1f} M "
              f"| {t_on:.1f} | {t_off:.1f} ({conv:.1f}) | {t_off / t_on:.1f}× | {pre:.1f} |")


def main():
    if len(sys.argv) != 2 or not os.path.isdir(sys.argv[1]):
        print("usage: tools/gpu_bench_table.py OUT_DIR (a folder tools/gpu_bench.sh wrote)",
              file=sys.stderr)
        sys.exit(2)
    runs = load(sys.argv[1])
    if not runs:
        print(f"tools/gpu_bench_table.py: no bench reports (*.json) in {sys.argv[1]}",
              file=sys.stderr)
        sys.exit(2)
    devices = {(r["device"], r["driver"]) for r in runs.values()}
    for device, driver in sorted(devices):
        print(f"Device: {device}, driver {driver}")
    print()
    table3(runs)
    off_axis(runs)


if __name__ == "__main__":
    main()
