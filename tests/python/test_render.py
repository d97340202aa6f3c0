"""The renderer from NumPy: equal to the CLI on the same arrays, light-conserving, reusing its
kernels, and refusing bad arguments with the CLI's messages."""

import subprocess

import numpy as np
import pytest

import ocular_render as oc

# A narrow field (3.3 arcmin per pixel) so that a dioptre of defocus spans a few pixels.
W, H, FOV = 96, 54, 3.0


def two_planes():
    """A textured near plane (0.5 m) on the left and a far one (4 m) on the right."""
    y, x = np.mgrid[0:H, 0:W]
    checker = ((x // 6 + y // 6) % 2).astype(np.float32)
    color = np.stack([10 + 90 * checker, 20 + 40 * checker, 5 + 60 * (1 - checker)], axis=-1)
    depth = np.where(x < W // 2, 0.5, 4.0).astype(np.float32)
    return color.astype(np.float32), depth


def test_python_render_equals_the_cli_render_of_the_same_arrays(tmp_path, cli, kernel_cache):
    color, depth = two_planes()
    oc.write_exr(tmp_path / "c.exr", color)
    oc.write_exr(tmp_path / "d.exr", depth)
    out = tmp_path / "cli.exr"
    subprocess.run(
        [cli, "render", "--color", str(tmp_path / "c.exr"), "--depth", str(tmp_path / "d.exr"),
         "--fov-y", str(FOV), "--eye", "astigmatism", "--focus-m", "0.5", "--pupil-mm", "4",
         "--cache", str(kernel_cache), "-o", str(out)],
        check=True, capture_output=True,
    )
    from_cli = oc.read_exr(out)
    fresh = oc.Renderer(cache_dir=kernel_cache)
    eye = oc.Eye.preset("astigmatism")
    ours = fresh.render(eye, color, depth, fov_y_deg=FOV, focus_m=0.5, pupil_mm=4.0)
    assert ours.shape == (H, W, 3) and ours.dtype == np.float32
    scale = float(np.abs(from_cli).max())
    assert np.abs(ours - from_cli).max() <= 1e-6 * scale
    # Negative control: through a 2 mm pupil (half the blur) the image is not within that bar.
    other = fresh.render(eye, color, depth, fov_y_deg=FOV, focus_m=0.5, pupil_mm=2.0)
    assert np.abs(other - from_cli).max() > 1e-2 * scale


def test_a_uniform_plane_keeps_its_colour(renderer):
    # A plane of one colour at one depth convolves to itself where the PSF stays inside the
    # frame: every kernel sums to one (light is conserved).
    color = np.empty((H, W, 3), np.float32)
    color[...] = (3.0, 7.0, 11.0)
    depth = np.full((H, W), 2.0, np.float32)
    eye = oc.Eye.preset("myopia")
    with pytest.warns(UserWarning, match="2 m at every pixel"):
        out = renderer.render(eye, color, depth, fov_y_deg=30.0, focus_m=2.0, pupil_mm=5.0)
    interior = out[16:-16, 16:-16]
    assert np.allclose(interior, (3.0, 7.0, 11.0), rtol=2e-3)


def test_frames_reuse_the_kernels_while_the_eye_state_holds(kernel_cache):
    r = oc.Renderer(cache_dir=kernel_cache)
    color, depth = two_planes()
    eye = oc.Eye.preset("healthy")
    first = r.render(eye, color, depth, fov_y_deg=FOV, focus_m=1.0, pupil_mm=3.0)
    shifted = np.roll(color, 5, axis=1)
    second = r.render(eye, shifted, depth, fov_y_deg=FOV, focus_m=1.0, pupil_mm=3.0)
    assert r.stats == {"frames": 2, "kernel_preparations": 1}
    assert r.last_frame["kernels_reused"] is True
    assert r.last_frame["seconds_kernels"] == 0.0
    assert not np.array_equal(first, second)
    # a new pupil is a new eye state, whose kernels take time
    r.render(eye, color, depth, fov_y_deg=FOV, focus_m=1.0, pupil_mm=4.0)
    assert r.stats["kernel_preparations"] == 2
    assert r.last_frame["pupil_mm"] == 4.0 and r.last_frame["kernels_reused"] is False
    assert r.last_frame["seconds_kernels"] > 0.0


def test_default_focus_and_pupil_follow_the_cli(renderer):
    color, depth = two_planes()
    renderer.render(oc.Eye.preset("healthy"), color, depth, fov_y_deg=FOV)
    last = renderer.last_frame
    # the depth at the frame centre (W/2 is in the far half): 4 m along the view axis
    assert last["focus_from"].startswith("the default focus")
    assert 0.24 < last["focus_d"] <= 0.2501
    assert last["pupil_from"].startswith("Watson–Yellott")


def test_scene_rendering_matches_its_rasterised_arrays(renderer):
    eye = oc.Eye.preset("myopia")
    color, depth, fov = renderer.rasterize("primitives", size=(W, H))
    assert color.shape == (H, W, 3) and depth.shape == (H, W) and fov > 0
    from_scene = renderer.render_scene("primitives", eye, size=(W, H), pupil_mm=5.0)
    focus_d = renderer.last_frame["focus_d"]
    from_arrays = renderer.render(eye, color, depth, fov_y_deg=fov, focus_d=focus_d, pupil_mm=5.0)
    scale = float(np.abs(from_arrays).max())
    assert np.abs(from_scene - from_arrays).max() <= 1e-4 * scale


def bad_calls():
    color, depth = two_planes()
    eye = oc.Eye.preset("myopia")
    nan_depth = depth.copy()
    nan_depth[3, 7] = np.nan
    return [
        ("wrong shape", dict(color=color[..., :2]), ValueError,
         r"^color: shape \(54, 96, 2\) where \(H, W, 3\) linear RGB is required"),
        ("depth shape", dict(depth=depth[:-1]), ValueError,
         r"^depth: shape \(53, 96\) where \(54, 96\) is required"),
        ("float64", dict(color=color.astype(np.float64)), ValueError,
         r"^color: dtype float64 where float32 is required; convert with color.astype\(numpy.float32\)$"),
        ("nan depth", dict(depth=nan_depth), ValueError,
         r"^depth: 1 pixel\(s\) have invalid depth \(NaN, negative or -inf\), first at \(7, 3\)"),
        ("pupil", dict(pupil_mm=0.5), ValueError, r"^--pupil-mm 0.5 is outside 1 to 9 mm$"),
        ("pupil high", dict(pupil_mm=9.5), ValueError, r"^--pupil-mm 9.5 is outside 1 to 9 mm$"),
        ("fov", dict(fov_y_deg=200.0), ValueError, r"^--fov-y 200 is outside 0.1 to 170 degrees$"),
        ("method", dict(method="magic"), ValueError, r'^--method "magic" is not allowed'),
        ("layers", dict(layers=2, method="reference"), ValueError, r"^--layers applies to --method splat"),
        ("list", dict(color=color.tolist()), TypeError, r"^color: expected a numpy.ndarray of float32, got list$"),
    ], (eye, color, depth)


@pytest.mark.parametrize("case", range(10))
def test_bad_render_arguments_raise_with_the_message(renderer, case):
    cases, (eye, color, depth) = bad_calls()
    _, change, error, message = cases[case]
    args = dict(color=color, depth=depth, fov_y_deg=FOV, focus_m=1.0, pupil_mm=4.0)
    args.update(change)
    with pytest.raises(error, match=message):
        renderer.render(eye, args.pop("color"), args.pop("depth"), **args)


def test_unknown_scene_and_device(renderer):
    with pytest.raises(ValueError):
        renderer.render_scene("no-such-scene", oc.Eye.preset("myopia"), size=(32, 18))
    with pytest.raises(ValueError, match=r"no device matches"):
        oc.Renderer(device="no-such-gpu")


def test_other_threads_run_while_the_library_works(renderer):
    # With the GIL held through a call, a ticking thread would stall for the call's length.
    import threading
    import time

    ticks, stop = [], threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.002)

    thread = threading.Thread(target=tick)
    thread.start()
    try:
        color, depth = two_planes()
        started = time.perf_counter()
        renderer.render(oc.Eye.preset("keratoconus"), color, depth, fov_y_deg=FOV, focus_m=0.7,
                        pupil_mm=6.0, method="reference")
        oc.Eye.from_rx("-1.00 -0.50 x 90", pupil_mm=4.0)
        finished = time.perf_counter()
    finally:
        stop.set()
        thread.join()
    inside = [t for t in ticks if started <= t <= finished]
    gaps = np.diff([started, *inside, finished])
    assert finished - started > 0.2
    assert gaps.max() < 0.25 * (finished - started), (gaps.max(), finished - started)


def test_a_missing_vulkan_driver_is_a_runtime_error_saying_what_to_install():
    import os
    import subprocess
    import sys

    env = dict(os.environ, VK_DRIVER_FILES="/nonexistent/icd.json", OCULAR_VALIDATION="")
    env.pop("VK_ICD_FILENAMES", None)
    env.pop("OCULAR_DEVICE", None)
    code = (
        "import ocular_render as oc\n"
        "try:\n    oc.Renderer()\n"
        "except RuntimeError as e:\n    print('RuntimeError:', e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout
    assert out.startswith("RuntimeError: no Vulkan device found"), out
    assert "apt-get install mesa-vulkan-drivers" in out


def test_layered_arrays_let_hidden_surfaces_show_through_blurred_edges(renderer):
    # Layer 0: a near plane (0.5 m) on the left, a far one (4 m) on the right; layer 1: a
    # bright far surface behind the near plane. Focused far, the near plane's edge is blurred
    # and only the layered frame can show what it hides there.
    color, depth = two_planes()
    hidden_color = np.zeros_like(color)
    hidden_color[...] = (500.0, 500.0, 500.0)
    hidden_depth = np.where(depth < 1.0, 4.0, np.inf).astype(np.float32)
    colors = np.stack([color, hidden_color])
    depths = np.stack([depth, hidden_depth])
    eye = oc.Eye.preset("healthy")
    args = dict(fov_y_deg=FOV, focus_m=4.0, pupil_mm=5.0)
    one = renderer.render(eye, colors, depths, layers=1, **args)
    assert np.array_equal(one, renderer.render(eye, color, depth, **args))
    two = renderer.render(eye, colors, depths, layers=2, **args)
    assert two.shape == (H, W, 3)
    assert np.abs(two - one).max() > 1.0


def test_default_focus_and_pupil_render_as_the_cli_does(tmp_path, cli, kernel_cache):
    # No focus and no pupil: both resolve them from the frame (the depth at its centre, the
    # Watson–Yellott pupil of its mean luminance at 30 years) and must agree to the bit.
    color, depth = two_planes()
    color = color * np.float32(0.05)  # a dim frame: a wide pupil
    oc.write_exr(tmp_path / "c.exr", color)
    oc.write_exr(tmp_path / "d.exr", depth)
    out = tmp_path / "cli.exr"
    subprocess.run(
        [cli, "render", "--color", str(tmp_path / "c.exr"), "--depth", str(tmp_path / "d.exr"),
         "--fov-y", str(FOV), "--eye", "healthy", "--cache", str(kernel_cache), "-o", str(out)],
        check=True, capture_output=True,
    )
    r = oc.Renderer(cache_dir=kernel_cache)
    ours = r.render(oc.Eye.preset("healthy"), color, depth, fov_y_deg=FOV)
    assert r.last_frame["pupil_mm"] > 5.0
    from_cli = oc.read_exr(out)
    assert np.abs(ours - from_cli).max() <= 1e-6 * float(np.abs(from_cli).max())


def smooth_plane():
    """A smooth texture (cd/m²) on a plane at 0.25 m: 3.75 D out of focus when focused at 4 m."""
    y, x = np.mgrid[0:H, 0:W].astype(np.float32)
    color = np.stack([50 + 10 * np.sin(0.2 * x), 40 + 10 * np.cos(0.15 * y),
                      30 + 10 * np.sin(0.1 * (x + y))], axis=-1).astype(np.float32)
    return color, np.full((H, W), 0.25, np.float32)


def test_the_merge_bound_follows_the_white_the_image_is_shown_at(renderer):
    # A smooth texture on a plane 3.75 D out of focus, shown with white at 64 cd/m², where the
    # colour rule lets blocks merge. The same frame ×1024 shown 10 EV darker is the
    # same picture: the merge decisions and so the image scale exactly. Kept at the first white
    # (the rule applied in the frame's own units) the bright frame merges fewer blocks and
    # renders differently.
    color, depth = smooth_plane()
    eye = oc.Eye.preset("healthy")
    args = dict(fov_y_deg=FOV, focus_m=4.0, pupil_mm=5.0)
    with pytest.warns(UserWarning):
        base = renderer.render(eye, color, depth, exposure_ev=-6.0, **args)
        scaled = renderer.render(eye, color * 1024, depth, exposure_ev=-16.0, **args)
        same_white = renderer.render(eye, color * 1024, depth, exposure_ev=-6.0, **args)
    assert np.abs(scaled / 1024 - base).max() <= 1e-6 * np.abs(base).max()
    # merging moves a pixel by a fraction of an 8-bit step: measured 6.7e-5 of the brightest
    assert np.abs(same_white / 1024 - base).max() > 1e-5 * np.abs(base).max()
    with pytest.raises(ValueError, match=r"^exposure_ev NaN must be a number of EV in \[-64, 64\]$"):
        renderer.render(eye, color, depth, exposure_ev=float("nan"), **args)


def test_the_quality_preset_changes_the_work_and_a_bad_one_is_refused(renderer):
    # The textured plane of the merge-bound test: `exact` merges nothing, `fast` merges blocks
    # as wide as the blur; both stay close to each other (a fraction of the signal) and differ.
    color, depth = smooth_plane()
    eye = oc.Eye.preset("healthy")
    args = dict(fov_y_deg=FOV, focus_m=4.0, pupil_mm=5.0, exposure_ev=-6.0)
    with pytest.warns(UserWarning):
        exact = renderer.render(eye, color, depth, quality="exact", **args)
        fast = renderer.render(eye, color, depth, quality="fast", **args)
    difference = np.abs(fast - exact).max() / np.abs(exact).max()
    assert 0 < difference < 0.05, difference
    with pytest.raises(ValueError, match=r'^--quality "fastest" is not one of exact, balanced, fast$'):
        renderer.render(eye, color, depth, quality="fastest", **args)


def test_a_binocular_pair_equals_the_cli_pair(tmp_path, cli, kernel_cache):
    r = oc.Renderer(cache_dir=kernel_cache)
    left, right = r.render_scene_pair(
        "primitives", oc.Eye.preset("healthy"), oc.Eye.preset("myopia"), size=(64, 36),
        focus_m=0.5, pupil_mm=3.0, age=55, quality="fast")
    assert left.shape == right.shape == (36, 64, 3)
    out = tmp_path / "pair.exr"
    subprocess.run(
        [cli, "render", "--scene", "primitives", "--size", "64x36", "--eye", "healthy",
         "--eye-right", "myopia", "--focus-m", "0.5", "--pupil-mm", "3", "--age", "55",
         "--quality", "fast", "--cache", str(kernel_cache), "-o", str(out)],
        check=True, capture_output=True)
    for ours, side in ((left, "left"), (right, "right")):
        theirs = oc.read_exr(tmp_path / f"pair-{side}.exr")[..., :3]
        scale = float(np.abs(theirs).max())
        assert np.abs(ours - theirs).max() <= 1e-6 * scale, side
    pair = r.last_pair
    # the healthy eye reaches 2 D with the least accommodation; the -6 D myope's far point is
    # nearer than 0.5 m, so it stays relaxed and keeps a negative defocus
    assert pair["driver"] == "left"
    assert abs(pair["residual_d"][0]) < 0.05 and pair["residual_d"][1] < -3.0
    assert not np.allclose(left, right)
    with pytest.raises(ValueError, match="--ipd-mm"):
        r.render_scene_pair("primitives", oc.Eye.preset("healthy"), ipd_mm=10.0)


def test_a_headset_frame_equals_the_cli_headset_frame(tmp_path, cli, kernel_cache):
    r = oc.Renderer(cache_dir=kernel_cache)
    ours = r.render_scene("primitives", oc.Eye.preset("healthy"), headset="vive-pro",
                          focus_m=0.5, pupil_mm=3.0, quality="fast")
    assert ours.shape == (1600, 1440, 3)
    out = tmp_path / "vr.exr"
    subprocess.run(
        [cli, "render", "--scene", "primitives", "--headset", "vive-pro", "--eye", "healthy",
         "--focus-m", "0.5", "--pupil-mm", "3", "--quality", "fast", "--cache",
         str(kernel_cache), "-o", str(out)],
        check=True, capture_output=True)
    theirs = oc.read_exr(out)[..., :3]
    assert np.abs(ours - theirs).max() <= 1e-6 * float(np.abs(theirs).max())
    with pytest.raises(ValueError, match="headset or size"):
        r.render_scene("primitives", oc.Eye.preset("healthy"), headset="quest3", size=(64, 36))
    with pytest.raises(ValueError, match="quest3, vive-pro"):
        r.render_scene_pair("primitives", oc.Eye.preset("healthy"), headset="rift")
