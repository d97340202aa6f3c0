#!/usr/bin/env python3
"""The table of tools/gpu_vs_old.sh's runs: per scene, eye and size, the new engine's GPU time
split into the draw (raster, resolve) and the splat passes (everything else), its wall
time, the old engine's, and their ratios; beside them the new engine with 2×2 merging only.

    tools/gpu_vs_old_table.py OUT_DIR

Every number is read from the `ocular bench --json` reports: only sums and ratios are computed.
"""
import json
import os
import sys

# "depth resolve" is the resolve's name in reports before it resolved colour too
DRAW = {"raster", "resolve", "depth resolve", "peel"}


def load(folder, name):
    path = os.path.join(folder, name + ".json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def split(report):
    draw = sum(p["mean_ms"] for p in report["passes"] if p["name"] in DRAW)
    splat = sum(p["mean_ms"] for p in report["passes"] if p["name"] not in DRAW)
    return draw, splat


def fmt_entries(n):
    return f"{n / 1e6:.2f} M" if n >= 1e5 else f"{n / 1e3:.0f} k"


def main():
    folder = sys.argv[1]
    devices = open(os.path.join(folder, "devices.txt")).read().strip().splitlines()
    # `ocular devices` lists a header, then one line per device, the default marked with '*'.
    used = [d.lstrip("* ").strip() for d in devices if d.startswith("*") and "used by" not in d]
    print(f"device: {used[0] if used else '?'}\n")
    print("| scene | eye | size | new: draw + splat ms | new wall ms | old: draw + splat ms "
          "| old wall ms | splat, old ÷ new | entries new / old | evaluations per pixel | "
          "2×2 merging only: splat ms, evaluations per pixel |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    names = sorted({f[:-9] for f in os.listdir(folder) if f.endswith("_new.json")},
                   key=lambda s: (s.count("off-axis"), int(s.split("_")[2].split("x")[0]), s))
    for tag in names:
        new = load(folder, tag + "_new")
        old = load(folder, tag + "_old")
        lod = load(folder, tag + "_l1")
        scene, eye, size = tag.split("_")[:3]
        size = size.replace("x", "×")
        if "off-axis" in tag:
            size += " off axis"
        nd, ns = split(new)
        row = [scene, eye, size, f"{nd:.2f} + {ns:.2f}",
               f"{new['wall_ms_per_frame']['mean_ms']:.1f}"]
        if old:
            od, os_ = split(old)
            row += [f"{od:.2f} + {os_:.2f}", f"{old['wall_ms_per_frame']['mean_ms']:.1f}",
                    f"{os_ / ns:.2f}×",
                    f"{fmt_entries(new['list_entries'])} / {fmt_entries(old['list_entries'])}"]
        else:
            row += ["—", "—", "—", fmt_entries(new["list_entries"])]
        row.append(f"{new.get('evaluations_per_pixel', 0):.0f}")
        if lod:
            _, ls = split(lod)
            row.append(f"{ls:.2f}, {lod.get('evaluations_per_pixel', 0):.0f}")
        else:
            row.append("—")
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
