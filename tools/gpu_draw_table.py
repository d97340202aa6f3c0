#!/usr/bin/env python3
"""The tables of tools/gpu_draw.sh's runs: the draw's GPU time at 2, 4 and 8 samples per pixel
(and at 4 unshaded, and with its colour in half floats), and two eyes at a headset's panel against its refresh interval.

    tools/gpu_draw_table.py OUT_DIR

Every number is read from the `ocular bench --json` reports; only sums and ratios are computed.
The draw is the passes raster, resolve and peel (gpu_vs_old_table.py's split).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gpu_vs_old_table import load, split  # noqa: E402
from gpu_presets_table import device  # noqa: E402


def raster_ms(report):
    return sum(p["mean_ms"] for p in report["passes"] if p["name"] == "raster")


def main():
    folder = sys.argv[1]
    print(f"device: {device(folder)}\n")
    print("The draw (GPU ms per frame; raster pass alone in brackets), primitives and colonnade "
          "through the myopic eye, `fast`\n")
    print("| scene | size | 2 samples | 4 samples | 8 samples | 4 unshaded | 4, half colour | 8 / 2 |")
    print("|---|---|---|---|---|---|---|---|")
    for size in ["3840x2160", "1280x720"]:
        for scene in ["primitives", "colonnade"]:
            cells, draws = [], {}
            for n in (2, 4, 8):
                r = load(folder, f"samples{n}_{scene}_{size}")
                if r is None:
                    cells.append("—")
                    continue
                draws[n] = split(r)[0]
                cells.append(f"{draws[n]:.2f} ({raster_ms(r):.2f})")
            for prefix in ("unshaded", "half"):
                u = load(folder, f"{prefix}_{scene}_{size}")
                cells.append("—" if u is None else f"{split(u)[0]:.2f} ({raster_ms(u):.2f})")
            ratio = f"{draws[8] / draws[2]:.2f}×" if 2 in draws and 8 in draws else "—"
            print(f"| {scene} | {size} | " + " | ".join(cells) + f" | {ratio} |")
    print("\nTwo eyes at a headset's panel, `fast` (GPU ms per pair, both eyes' passes; "
          "the refresh interval is 11.1 ms)\n")
    print("| headset | scene / eye | one eye | pair | draw per eye | pair / one eye |")
    print("|---|---|---|---|---|---|")
    for headset in ["vive-pro", "quest3"]:
        for scene, eye in [("primitives", "myopia"), ("colonnade", "astigmatism")]:
            r = load(folder, f"pair_{headset}_{scene}_{eye}")
            if r is None or not r.get("binocular"):
                print(f"| {headset} | {scene} / {eye} | — | — | — | — |")
                continue
            b = r["binocular"]
            one, pair = r["total"]["mean_ms"], b["gpu_total"]["mean_ms"]
            draw = split(r)[0]
            print(f"| {headset} | {scene} / {eye} | {one:.2f} | {pair:.2f} | {draw:.2f} | "
                  f"{pair / one:.2f}× |")


if __name__ == "__main__":
    main()
