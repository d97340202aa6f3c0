#!/usr/bin/env python3
"""Speed/accuracy trade-off sweep of ocular's settings, in one command.

Renders one ground truth with `ocular compare` (default settings), then varies one setting at a
time around the defaults — object-distance samples, Rmax cap, merge thresholds, tile size, PSF
texture format, beta degree, PSF pitch — and records the splat image's quality against that
fixed truth (PSNR, MSSIM, mean FLIP at FLIP's default 67 pixels per degree), its GPU time and
its kernel evaluations per pixel (the cost without a clock, which lavapipe's timing noise does
not blur). Writes a CSV and a plot of quality against evaluations per pixel with the defaults
marked.

    tools/sweep.py                       # primitives, myopia eye, 320x180 → sweep/
    tools/sweep.py --eye keratoconus --size 640x360 --out sweep-kc
    tools/sweep.py --scene colonnade --eye astigmatism --size 640x360 --truth-in truth.exr

Needs a release build (`cargo build --release`); the plot needs matplotlib
(`pip install matplotlib`), the CSV does not. On lavapipe at 320x180 it takes a few minutes.
"""

import argparse
import csv
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BINARY = os.path.join(ROOT, "target", "release", "ocular")

# (setting name, flag, values); the first value listed in DEFAULTS is what `ocular` uses.
SWEEP = [
    ("object samples", "--object-samples", ["9", "21", "41", "81"]),
    ("Rmax cap", "--rmax-cap", ["4", "8", "16", "64"]),
    ("merge levels", "--merge-levels", ["0", "1", "2", "5"]),
    ("merge min radius", "--merge-min-radius", ["2", "5", "10"]),
    ("merge blur per block k", "--merge-blur-per-block", ["0", "1", "2", "4"]),
    # up to 1: colours averaged wherever the blur allows a block (level of detail by blur alone)
    ("merge colour error", "--merge-color-error", ["0.0039", "0.0156", "0.0625", "1"]),
    ("tile size", "--tile-size", ["8", "16", "32"]),
    ("texture format", "--texture-format", ["rgba16f", "rgba32f"]),
    # a switch: "on" passes the flag alone (the radius levels instead of the layer kernels)
    ("kernel reads: levels", "--level-kernels", ["on"]),
    ("beta degree", "--beta-degree", ["10", "20", "60", "160"]),
    ("PSF sample (um)", "--sample-um", ["2", "4", "8"]),
]
DEFAULTS = {
    "--object-samples": "41",
    "--rmax-cap": "64",
    "--merge-levels": "5",
    "--merge-min-radius": "5",
    "--merge-blur-per-block": "2",
    "--merge-color-error": "0.00098",
    "--tile-size": "8",
    "--texture-format": "rgba16f",
    "--level-kernels": "off",
    "--beta-degree": "160",
    "--sample-um": "4",
}


def compare(args, extra, out_json):
    cmd = [BINARY, "compare", "--scene", args.scene, "--eye", args.eye, "--size", args.size,
           "--no-slices", "--json", out_json] + extra
    started = time.time()
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"sweep: {' '.join(cmd)} failed:\n{result.stderr.strip()}")
    with open(out_json) as f:
        report = json.load(f)
    splat = next(m for m in report["methods"] if m["method"] == "splat")
    return splat, time.time() - started


def row(setting, value, splat, default):
    return {"setting": setting, "value": value, "psnr_db": splat["psnr_db"], "mssim": splat["mssim"],
            "flip": splat["flip_mean"], "gpu_ms": splat["gpu_ms"],
            "evaluations_per_pixel": splat["evaluations_per_pixel"], "default": default}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", default="primitives")
    parser.add_argument("--eye", default="myopia")
    parser.add_argument("--size", default="320x180")
    parser.add_argument("--out", default="sweep", help="output folder for sweep.csv and sweep.png")
    parser.add_argument("--truth-in", help="a ground truth saved by `ocular compare --truth-out` for the same scene, "
                        "eye and size (default: render it first)")
    args = parser.parse_args()
    if not os.path.exists(BINARY):
        sys.exit(f"sweep: {BINARY} is missing; run `cargo build --release` first")
    os.makedirs(args.out, exist_ok=True)
    truth = args.truth_in or os.path.join(args.out, "truth.exr")
    scratch = os.path.join(args.out, "run.json")

    print(f"ground truth: {args.scene}, eye {args.eye}, {args.size} (default settings)", flush=True)
    baseline, _ = compare(args, ["--truth-in" if args.truth_in else "--truth-out", truth], scratch)
    rows = [row("defaults", "", baseline, True)]
    for name, flag, values in SWEEP:
        for value in values:
            if value == DEFAULTS[flag]:
                continue
            extra = [flag] if value == "on" else [flag, value]
            splat, seconds = compare(args, ["--truth-in", truth] + extra, scratch)
            rows.append(row(name, value, splat, False))
            print(f"  {name:<24} {value:>8}: {splat['psnr_db'] or float('inf'):7.2f} dB  MSSIM {splat['mssim']:.5f}  "
                  f"FLIP {splat['flip_mean']:.4f}  GPU {splat['gpu_ms']:9.2f} ms  "
                  f"{splat['evaluations_per_pixel']:7.1f} evaluations/px  ({seconds:.0f} s)", flush=True)
    os.remove(scratch)

    csv_path = os.path.join(args.out, "sweep.csv")
    with open(csv_path + ".tmp", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    os.replace(csv_path + ".tmp", csv_path)
    print(f"wrote {csv_path}")

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("sweep: matplotlib is not installed (pip install matplotlib): no plot")
        return
    fig, ax = plt.subplots(figsize=(9, 5.5), dpi=110)
    settings = [s[0] for s in SWEEP]
    colours = plt.get_cmap("tab10")
    for i, name in enumerate(settings):
        pts = [r for r in rows if r["setting"] == name]
        ax.scatter([r["evaluations_per_pixel"] for r in pts], [r["psnr_db"] or 99.0 for r in pts],
                   color=colours(i % 10), label=name, s=28)
        for r in pts:
            ax.annotate(r["value"], (r["evaluations_per_pixel"], r["psnr_db"] or 99.0), fontsize=7, xytext=(3, 3),
                        textcoords="offset points")
    d = rows[0]
    ax.scatter([d["evaluations_per_pixel"]], [d["psnr_db"] or 99.0], marker="*", s=220, color="black",
               label="defaults", zorder=5)
    ax.set_xscale("log")
    ax.set_xlabel("kernel evaluations per pixel (pixel × fragment pairs in reach; log scale)")
    ax.set_ylabel("PSNR vs ground truth (dB)")
    ax.set_title(f"ocular speed/accuracy: {args.scene}, {args.eye} eye, {args.size}")
    ax.legend(fontsize=7, loc="lower right")
    ax.grid(alpha=0.3)
    png_path = os.path.join(args.out, "sweep.png")
    fig.tight_layout()
    fig.savefig(png_path + ".tmp.png")
    os.replace(png_path + ".tmp.png", png_path)
    print(f"wrote {png_path}")


if __name__ == "__main__":
    main()
