#!/usr/bin/env python3
"""Does an edge pixel's treatment matter? (issue 51, docs/validation.md "Silhouettes")

Today a pixel a silhouette crosses is one fragment: the average colour of its samples at the
nearest sample's depth. The alternative is to splat the surfaces it mixes apart. This probe
approximates that alternative by rendering the frame at twice the size, where each pixel of the
frame is four pixels that mostly show one surface each, and averaging 2×2 back down; both
renders use `quality="exact"` (no merging) and the same focus and pupil. Each is judged against
the multi-view truth (`ocular compare --truth views`, which resolves every pupil view's coverage
before it accumulates, so it mixes edge pixels as physics does), over the whole frame and over
the band within 8 px of a depth edge. If the doubled frame is much closer to the truth in the
band than the plain one, how a mixed pixel is split matters.

The doubled frame also samples the raster and the kernels twice as finely, so the probe bounds
the effect from above rather than isolating it.

Usage: tools/mixed_pixels.py [--bin target/release/ocular] [--out mixed_out]
Needs the Python package (pip install .) and the CLI.
"""

import argparse
import pathlib
import subprocess
import sys

import numpy as np

import ocular_render as oc

W, H = 320, 180
PUPIL_MM = 5.0


def psnr(a, b, peak):
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(peak * peak / mse)


def edge_band(depth, radius):
    """Pixels within `radius` of a 4-neighbour pair more than 0.05 D apart."""
    v = 1.0 / np.where(np.isfinite(depth) & (depth > 0), depth, 1e9)
    edge = np.zeros(depth.shape, bool)
    dx = np.abs(np.diff(v, axis=1)) > 0.05
    dy = np.abs(np.diff(v, axis=0)) > 0.05
    edge[:, :-1] |= dx
    edge[:, 1:] |= dx
    edge[:-1, :] |= dy
    edge[1:, :] |= dy
    band = edge.copy()
    for _ in range(radius):
        grown = band.copy()
        grown[1:, :] |= band[:-1, :]
        grown[:-1, :] |= band[1:, :]
        grown[:, 1:] |= band[:, :-1]
        grown[:, :-1] |= band[:, 1:]
        band = grown
    return band


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default="target/release/ocular")
    parser.add_argument("--out", default="mixed_out")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scene_text = (pathlib.Path(__file__).resolve().parents[1] / "scenes" / "primitives.toml").read_text()
    cases = [
        # blurred silhouettes before a sharp background: the paper's focus on the far letter
        ("far focus", "focus_m = 7.5", 7.5),
        # the other way round: the near sphere sharp, the background blurred
        ("near focus", "focus_m = 0.2", 0.2),
    ]
    renderer = oc.Renderer()
    print("| focus | eye | whole frame dB: plain → split (2× and back) | edge band dB: plain → split |")
    print("|---|---|---|---|")
    for label, focus_line, focus_m in cases:
        scene = out / f"primitives-{focus_m}.toml"
        scene.write_text(scene_text.replace("focus_m = 7.5", focus_line))
        c1, d1, fov = renderer.rasterize(str(scene), size=(W, H))
        c2, d2, _ = renderer.rasterize(str(scene), size=(2 * W, 2 * H))
        band = edge_band(d1, 8)
        for eye_name in ["healthy", "myopia"]:
            truth_path = out / f"truth-{eye_name}-{focus_m}.exr"
            subprocess.run(
                [args.bin, "compare", "--scene", str(scene), "--eye", eye_name, "--size", f"{W}x{H}",
                 "--truth", "views", "--pupil-mm", str(PUPIL_MM), "--no-slices",
                 "--truth-out", str(truth_path)],
                check=True, stdout=subprocess.DEVNULL,
            )
            truth = oc.read_exr(truth_path)[..., :3]
            eye = oc.Eye.preset(eye_name)
            common = dict(fov_y_deg=fov, focus_m=focus_m, pupil_mm=PUPIL_MM, quality="exact")
            plain = renderer.render(eye, c1, d1, **common)
            double = renderer.render(eye, c2, d2, **common)
            split = double.reshape(H, 2, W, 2, 3).mean(axis=(1, 3))
            peak = float(truth.max())
            cells = []
            for mask in (np.ones_like(band), band):
                cells.append(f"{psnr(plain[mask], truth[mask], peak):.2f} → {psnr(split[mask], truth[mask], peak):.2f}")
            print(f"| {label} | {eye_name} | {cells[0]} | {cells[1]} |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
