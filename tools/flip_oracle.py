#!/usr/bin/env python3
"""Regenerates tests/data/flip/: small synthetic image pairs and the FLIP maps that NVIDIA's
reference implementation (the `flip-evaluator` package, version 1.7) computes for them, which
tests/it/flip.rs holds ocular's FLIP to.

    python3 -m venv /tmp/flipvenv && /tmp/flipvenv/bin/pip install flip-evaluator==1.7 numpy
    /tmp/flipvenv/bin/python tools/flip_oracle.py

Images are raw little-endian float32, row-major, RGB (height x width x 3); maps are float32
(height x width). cases.json lists each case: its files, size, settings and the oracle's mean
and exposure range. The pairs are made here from a fixed seed, so rerunning gives the same
files.
"""

import json
import os

import numpy as np
import flip_evaluator as flip

OUT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "data", "flip")
W, H = 64, 48


def scene(rng):
    """A linear HDR image: a luminance ramp over three decades, coloured disks, a highlight."""
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    base = 0.02 * 1000.0 ** (x / (W - 1))
    img = np.stack([base, base * 0.8, base * 0.6], axis=-1)
    for cx, cy, r, colour in [(16, 16, 7, (0.9, 0.1, 0.05)), (40, 30, 9, (0.05, 0.6, 0.9)),
                              (52, 10, 4, (0.9, 0.9, 0.1))]:
        mask = (x - cx) ** 2 + (y - cy) ** 2 <= r * r
        img[mask] = np.array(colour) * (2.0 + cx / 10.0)
    img[22:25, 8:11] = 40.0
    img += rng.normal(0.0, 0.01, img.shape) * img
    return np.clip(img, 0.0, None)


def degrade(img, rng):
    """A test image: blurred a little, noisier, the highlight moved by one pixel."""
    out = img.copy()
    out[:, 1:-1] = 0.25 * img[:, :-2] + 0.5 * img[:, 1:-1] + 0.25 * img[:, 2:]
    out *= 1.0 + rng.normal(0.0, 0.05, img.shape)
    out[22:25, 8:11] = img[22:25, 7:10]
    out[22:25, 11] = 40.0
    return np.clip(out, 0.0, None)


def save(name, array):
    np.ascontiguousarray(array, dtype="<f4").tofile(os.path.join(OUT, name))


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = np.random.default_rng(20201)
    hdr_ref = scene(rng)
    hdr_test = degrade(hdr_ref, rng)
    # an LDR pair in linear [0, 1]: the HDR pair scaled and clipped
    ldr_ref = np.clip(hdr_ref / 4.0, 0.0, 1.0)
    ldr_test = np.clip(hdr_test / 4.0, 0.0, 1.0)
    for name, img in [("hdr_ref.f32", hdr_ref), ("hdr_test.f32", hdr_test),
                      ("ldr_ref.f32", ldr_ref), ("ldr_test.f32", ldr_test)]:
        save(name, img)
    cases = []
    runs = [
        ("ldr_67", "ldr", "LDR", {"ppd": 67.02064514160156}),
        ("ldr_30", "ldr", "LDR", {"ppd": 30.0}),
        ("hdr_aces_67", "hdr", "HDR", {"ppd": 67.02064514160156, "tonemapper": "aces"}),
        ("hdr_reinhard_30", "hdr", "HDR", {"ppd": 30.0, "tonemapper": "reinhard",
                                           "startExposure": -2.0, "stopExposure": 3.0, "numExposures": 4}),
        ("hdr_hable_67", "hdr", "HDR", {"ppd": 67.02064514160156, "tonemapper": "hable"}),
    ]
    for name, pair, mode, params in runs:
        ref = (hdr_ref if pair == "hdr" else ldr_ref).astype(np.float32)
        test = (hdr_test if pair == "hdr" else ldr_test).astype(np.float32)
        error_map, mean, used = flip.evaluate(ref, test, mode, inputsRGB=False, applyMagma=False,
                                              parameters=dict(params))
        error_map = np.asarray(error_map, dtype=np.float32).reshape(H, W)
        save(f"{name}_map.f32", error_map)
        case = {"name": name, "reference": f"{pair}_ref.f32", "test": f"{pair}_test.f32",
                "map": f"{name}_map.f32", "width": W, "height": H, "mode": mode,
                "ppd": params["ppd"], "mean": float(mean)}
        if mode == "HDR":
            case.update({"tone_mapper": used["tonemapper"].lower(), "start": float(used["startExposure"]),
                         "stop": float(used["stopExposure"]), "count": int(used["numExposures"]),
                         "range_given": "startExposure" in params})
        cases.append(case)
        print(f"{name}: mean {mean:.6f} {used}")
    with open(os.path.join(OUT, "cases.json.tmp"), "w") as f:
        json.dump({"generator": "tools/flip_oracle.py with flip-evaluator 1.7", "cases": cases}, f, indent=2)
    os.replace(os.path.join(OUT, "cases.json.tmp"), os.path.join(OUT, "cases.json"))


if __name__ == "__main__":
    main()
