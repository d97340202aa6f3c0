#!/bin/bash
# The --quality presets against issue #47's quality floors (docs/quality.md): for primitives,
# chart and colonnade through the four preset eyes, one exact CPU reference per case
# (`ocular compare`, computed once and read back), each preset's splat judged against it, and
# the sharp frame (no eye, `ocular raster`) judged against the same truth for scale: what the
# eye's blur itself changes. Prints a Markdown table with each floor checked, writes
# OUT/floors.csv and, where matplotlib is installed, OUT/floors.png (PSNR against kernel
# evaluations per pixel, one line per case from exact to fast).
# Usage: tools/quality_floors.sh [BINARY] [OUT_DIR] [SIZE]   (defaults: target/release/ocular, floors_out, 640x360)
# Runs that finished are kept: rerunning after an interruption resumes.
set -euo pipefail
bin=${1:-target/release/ocular}
out=${2:-floors_out}
size=${3:-640x360}
mkdir -p "$out"
for scene in primitives chart colonnade; do
  [ -s "$out/sharp-$scene.exr" ] || "$bin" raster --scene "$scene" --size "$size" -o "$out/sharp-$scene.exr" > /dev/null
  for eye in healthy myopia astigmatism keratoconus; do
    truth="$out/truth-$scene-$eye.exr"
    for q in exact balanced fast; do
      json="$out/$scene-$eye-$q.json"
      [ -s "$json" ] && continue
      args=(--truth-out "$truth")
      [ -s "$truth" ] && args=(--truth-in "$truth")
      "$bin" compare --scene "$scene" --eye "$eye" --size "$size" --quality "$q" --no-slices \
        "${args[@]}" --json "$json" > /dev/null
    done
    json="$out/$scene-$eye-sharp.json"
    [ -s "$json" ] || "$bin" compare --scene "$scene" --eye "$eye" --size "$size" --no-slices \
      --no-warmup --truth-in "$truth" --judge "$out/sharp-$scene.exr" --json "$json" > /dev/null
  done
done
python3 - "$out" <<'PY'
import csv, json, sys
out = sys.argv[1]
rows = []
for scene in ["primitives", "chart", "colonnade"]:
    for eye in ["healthy", "myopia", "astigmatism", "keratoconus"]:
        sharp = json.load(open(f"{out}/{scene}-{eye}-sharp.json"))
        s = next(m for m in sharp["methods"] if m["method"] == f"sharp-{scene}")
        row = {"scene": scene, "eye": eye, "sharp_psnr": s["psnr_db"], "sharp_flip": s["flip_mean"]}
        for q in ["exact", "balanced", "fast"]:
            r = json.load(open(f"{out}/{scene}-{eye}-{q}.json"))
            m = next(m for m in r["methods"] if m["method"] == "splat")
            row[f"{q}_psnr"] = m["psnr_db"] if m["psnr_db"] is not None else float("inf")
            row[f"{q}_flip"] = m["flip_mean"]
            row[f"{q}_evals"] = m["evaluations_per_pixel"]
            row[f"{q}_reads"] = m["texture_reads_per_pixel"]
            row[f"{q}_s"] = m["seconds"]
        rows.append(row)
with open(f"{out}/floors.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)
first = json.load(open(f"{out}/primitives-healthy-fast.json"))
print(f"{first['width']}×{first['height']} on {first['device']}; FLIP: mean of the displayed "
      f"images at {first['flip_ppd']:.2f} px/deg; every row judged against the exact reference")
print()
print("| scene / eye | no eye PSNR / FLIP | exact | balanced | fast | fast: evals, reads / px | floors (fast) |")
print("|---|---|---|---|---|---|---|")
fails = 0
for r in rows:
    checks = []
    if r["scene"] == "primitives":
        checks.append(("≥ 50 dB", r["fast_psnr"] >= 50.0))
        checks.append(("≥ no eye + 10 dB", r["fast_psnr"] >= r["sharp_psnr"] + 10.0))
    else:
        checks.append(("within 3 dB of balanced", r["fast_psnr"] >= r["balanced_psnr"] - 3.0))
    checks.append(("FLIP ≤ no eye / 5", r["fast_flip"] <= r["sharp_flip"] / 5.0))
    fails += sum(1 for _, ok in checks if not ok)
    cell = lambda q: f"{r[q + '_psnr']:.2f} dB / {r[q + '_flip']:.4f}"
    floors = "; ".join(f"{name} {'✓' if ok else '✗'}" for name, ok in checks)
    print(f"| {r['scene']} / {r['eye']} | {r['sharp_psnr']:.2f} dB / {r['sharp_flip']:.4f} | "
          f"{cell('exact')} | {cell('balanced')} | {cell('fast')} | "
          f"{r['fast_evals']:.1f}, {r['fast_reads']:.1f} | {floors} |")
print()
print(f"{fails} floor(s) missed")
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.exit(0)
fig, ax = plt.subplots(figsize=(9, 4.5))
colours = {"healthy": "tab:green", "myopia": "tab:blue", "astigmatism": "tab:orange",
           "keratoconus": "tab:red"}
styles = {"primitives": ("o", "-"), "chart": ("s", "--"), "colonnade": ("^", ":")}
for r in rows:
    xs = [r[f"{q}_evals"] for q in ["exact", "balanced", "fast"]]
    ys = [min(r[f"{q}_psnr"], 120.0) for q in ["exact", "balanced", "fast"]]
    marker, line = styles[r["scene"]]
    ax.plot(xs, ys, marker=marker, linestyle=line, color=colours[r["eye"]],
            label=f"{r['scene']} / {r['eye']}")
ax.set_xscale("log")
ax.set_xlabel("kernel evaluations per pixel (exact → balanced → fast)")
ax.set_ylabel("PSNR against the exact reference (dB)")
ax.grid(True, alpha=0.3)
ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
fig.tight_layout()
fig.savefig(f"{out}/floors.png", dpi=120)
PY
