#!/usr/bin/env python3
"""Times what a live change of eye state costs through the Python Renderer (the path a viewer
uses), warm process, no kernel cache: the default scene (primitives, 1280x720, the myopic eye,
its own focus), then the pupil 4 -> 5 mm, then a new spectacle prescription in front of the
eye. Prints each frame's kernel seconds (planning, focusing, computing the kernels, preparing
the splatter) and its render seconds; --json for scripts.

Usage: python tools/new_eye_state.py [--size 1280x720] [--json]
"""
import argparse
import json
import time

import ocular_render as oc


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    r = oc.Renderer(kernel_cache=False)
    eye = oc.Eye.preset("myopia")
    steps = [
        ("first frame (warm-up), pupil 4 mm", eye, 4.0),
        ("pupil 4 -> 5 mm", eye, 5.0),
        ("prescription -1.00 -0.50 x 90 in front", eye.with_correction("-1.00 -0.50 x 90"), 5.0),
        ("pupil 5 -> 4 mm", eye, 4.0),
    ]
    rows = []
    for name, e, pupil in steps:
        t = time.perf_counter()
        r.render_scene("primitives", e, size=(w, h), pupil_mm=pupil)
        wall = time.perf_counter() - t
        last = r.last_frame
        rows.append(
            {
                "step": name,
                "seconds_kernels": last["seconds_kernels"],
                "seconds_frame": last["seconds"],
                "seconds_wall": wall,
            }
        )
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    print(f"{'step':<42} {'kernels s':>10} {'frame s':>8} {'wall s':>8}")
    for row in rows:
        print(
            f"{row['step']:<42} {row['seconds_kernels']:>10.2f} "
            f"{row['seconds_frame']:>8.2f} {row['seconds_wall']:>8.2f}"
        )


if __name__ == "__main__":
    main()
