#!/usr/bin/env python3
"""Per-frame time of ocular_render's Renderer against `ocular bench` on the same frames.

    python tools/python_bench.py [--frames 100] [--warmup 5] [--size 320x180]
        [--scene primitives] [--eye myopia] [--ocular target/release/ocular] [--json OUT]

Runs `ocular bench` (the scene drawn and splatted in one submission per frame, wall time per
frame with upload and read-back), then, in this process, the same scene frame through one
Renderer: the frame rasterised once to arrays and rendered `--frames` times with render()
(upload, splat, read-back, NumPy copies), and as many times with render_scene() (the scene
drawn again each frame, as bench does), at bench's focus and pupil, after the same warm-up.
Prints both means and medians and the ratios; the bar is 1.2× bench's mean.
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import ocular_render as oc

REPO = pathlib.Path(__file__).resolve().parents[1]


def stat(samples_ms):
    s = sorted(samples_ms)
    return {
        "mean_ms": statistics.fmean(s),
        "median_ms": statistics.median(s),
        "p95_ms": s[max(0, -(-95 * len(s) // 100) - 1)],
    }


def timed(frames, render, renderer, overheads=None):
    """Wall ms per frame; with `overheads`, also collects each frame's wall time beyond the
    library's own (Renderer.last_frame["seconds"]): what the binding adds."""
    out = []
    for _ in range(frames):
        t = time.perf_counter()
        render()
        wall = time.perf_counter() - t
        out.append(1e3 * wall)
        if overheads is not None:
            overheads.append(1e3 * (wall - renderer.last_frame["seconds"]))
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--frames", type=int, default=100)
    p.add_argument("--warmup", type=int, default=5)
    p.add_argument("--size", default="320x180")
    p.add_argument("--scene", default="primitives")
    p.add_argument("--eye", default="myopia")
    p.add_argument("--ocular", default=os.environ.get("OCULAR_BIN", str(REPO / "target/release/ocular")))
    p.add_argument("--cache", type=pathlib.Path, default=None, help="kernel cache (default: a temporary one)")
    p.add_argument("--json", type=pathlib.Path, default=None)
    a = p.parse_args()
    width, height = (int(v) for v in a.size.lower().split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        cache = a.cache or pathlib.Path(tmp) / "kernels"
        bench_json = pathlib.Path(tmp) / "bench.json"
        subprocess.run(
            [a.ocular, "bench", "--scene", a.scene, "--eye", a.eye, "--size", a.size,
             "--frames", str(a.frames), "--warmup", str(a.warmup), "--cache", str(cache),
             "--json", str(bench_json)],
            check=True, stdout=subprocess.DEVNULL,
        )
        bench = json.loads(bench_json.read_text())
        focus_d, pupil_mm = bench["focus_d"], bench["pupil_mm"]

        renderer = oc.Renderer(cache_dir=cache)
        eye = oc.Eye.preset(a.eye)
        color, depth, fov = renderer.rasterize(a.scene, size=(width, height))

        def arrays():
            renderer.render(eye, color, depth, fov_y_deg=fov, focus_d=focus_d, pupil_mm=pupil_mm)

        def scene():
            renderer.render_scene(a.scene, eye, size=(width, height), focus_d=focus_d, pupil_mm=pupil_mm)

        results = {}
        for name, render in (("render", arrays), ("render_scene", scene)):
            timed(a.warmup, render, renderer)
            overheads = []
            results[name] = stat(timed(a.frames, render, renderer, overheads))
            results[name]["binding_overhead_ms"] = statistics.fmean(overheads)
        assert renderer.stats["kernel_preparations"] == 1, renderer.stats

    bench_ms = bench["wall_ms_per_frame"]
    report = {
        "device": renderer.device,
        "scene": a.scene,
        "eye": a.eye,
        "size": [width, height],
        "frames": a.frames,
        "warmup": a.warmup,
        "focus_d": focus_d,
        "pupil_mm": pupil_mm,
        "bench_wall_ms_per_frame": bench_ms,
        "python": results,
        "ratio_render": results["render"]["mean_ms"] / bench_ms["mean_ms"],
        "ratio_render_scene": results["render_scene"]["mean_ms"] / bench_ms["mean_ms"],
    }
    print(f"{a.scene} through {a.eye} at {width}×{height}, {a.frames} frames after {a.warmup} warm-up, on {renderer.device}")
    print(f"  ocular bench wall per frame   mean {bench_ms['mean_ms']:10.2f} ms   median {bench_ms['median_ms']:10.2f} ms")
    for name, r in results.items():
        ratio = r["mean_ms"] / bench_ms["mean_ms"]
        print(
            f"  Renderer.{name:<19} mean {r['mean_ms']:10.2f} ms   median {r['median_ms']:10.2f} ms   "
            f"{ratio:.3f}× bench (binding adds {r['binding_overhead_ms']:.2f} ms)"
        )
    if a.json:
        a.json.write_text(json.dumps(report, indent=2))
    worst = max(report["ratio_render"], report["ratio_render_scene"])
    print(f"  {'within' if worst <= 1.2 else 'NOT within'} 1.2× of bench (worst {worst:.3f}×)")


if __name__ == "__main__":
    sys.exit(main())
