#!/usr/bin/env python3
"""Builds a small dataset with ocular_render: N eyes fitted to random spectacle prescriptions,
K frames of a scene through each (a focus sweep), each image saved as EXR beside the eye file
it was rendered through, and a manifest.json tying them together.

    python tools/python_dataset.py OUT_DIR [--eyes 4] [--frames 3] [--size 160x90]
        [--scene primitives] [--seed 0] [--cache DIR]

One Renderer serves every frame: the device, pipelines and rasteriser are made once, and each
eye's kernels once per focus. CI runs it at 160×90 with 2 eyes × 2 frames (tests/python).
"""

import argparse
import json
import math
import pathlib
import random
import sys
import time

import numpy as np

import ocular_render as oc


def prescription(rng):
    """A plausible spectacle prescription: sphere −6…+2 D, cylinder −2.5…0 D (0.25 D steps)."""
    sphere = rng.randrange(-24, 9) * 0.25
    cylinder = -rng.randrange(0, 11) * 0.25
    axis = rng.randrange(1, 181)
    return sphere, cylinder, axis


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", type=pathlib.Path)
    p.add_argument("--eyes", type=int, default=4)
    p.add_argument("--frames", type=int, default=3, help="frames per eye (a focus sweep)")
    p.add_argument("--size", default="160x90", help="WxH")
    p.add_argument("--scene", default="primitives")
    p.add_argument("--pupil-mm", type=float, default=4.0)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--cache", type=pathlib.Path, default=None, help="kernel cache folder")
    a = p.parse_args()
    try:
        width, height = (int(v) for v in a.size.lower().split("x"))
    except ValueError:
        p.error(f"--size {a.size!r}: expected WxH, e.g. 160x90")
    if a.eyes < 1 or a.frames < 1:
        p.error("--eyes and --frames must be at least 1")

    started = time.monotonic()
    rng = random.Random(a.seed)
    a.out.mkdir(parents=True, exist_ok=True)
    renderer = oc.Renderer(cache_dir=a.cache)
    color, depth, fov = renderer.rasterize(a.scene, size=(width, height))
    oc.write_exr(a.out / "input_color.exr", color)
    oc.write_exr(a.out / "input_depth.exr", depth)
    # The sweep spans the scene's depths: from its nearest surface to its farthest (finite).
    finite = depth[np.isfinite(depth)]
    near_m, far_m = float(finite.min()), float(finite.max())
    focus_m = [
        near_m * (far_m / near_m) ** (k / max(a.frames - 1, 1)) for k in range(a.frames)
    ]
    eyes = []
    for i in range(a.eyes):
        s, c, ax = prescription(rng)
        rx = f"{s:+.2f} {c:+.2f} x {ax}"
        eye = oc.Eye.from_rx(rx, pupil_mm=a.pupil_mm)
        eye_file = f"eye_{i:03d}.toml"
        eye.save(a.out / eye_file)
        frames = []
        for k, f in enumerate(focus_m):
            image = renderer.render(eye, color, depth, fov_y_deg=fov, focus_m=f, pupil_mm=a.pupil_mm)
            name = f"eye_{i:03d}_frame_{k:02d}.exr"
            oc.write_exr(a.out / name, image)
            last = renderer.last_frame
            frames.append(
                {
                    "image": name,
                    "focus_m": f,
                    "focus_reached_d": last["focus_reached_d"],
                    "pupil_mm": last["pupil_mm"],
                }
            )
        a2 = math.radians(2 * ax)
        eyes.append(
            {
                "eye_file": eye_file,
                "rx": rx,
                "rx_power_vector_d": [s + c / 2, -c / 2 * math.cos(a2), -c / 2 * math.sin(a2)],
                "frames": frames,
            }
        )
    manifest = {
        "scene": a.scene,
        "size": [width, height],
        "fov_y_deg": fov,
        "inputs": {"color": "input_color.exr", "depth": "input_depth.exr"},
        "device": renderer.device,
        "eyes": eyes,
    }
    tmp = a.out / "manifest.json.tmp"
    tmp.write_text(json.dumps(manifest, indent=2))
    tmp.replace(a.out / "manifest.json")
    print(
        f"{a.out}: {a.eyes} eyes × {a.frames} frames at {width}×{height} in "
        f"{time.monotonic() - started:.1f} s ({renderer.stats['kernel_preparations']} kernel "
        f"preparations)"
    )


if __name__ == "__main__":
    try:
        main()
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        sys.exit(2)
