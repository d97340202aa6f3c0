"""The dataset example of tools/ runs end to end at 160×90 within CI's minute."""

import json
import pathlib
import subprocess
import sys
import time

import ocular_render as oc

REPO = pathlib.Path(__file__).resolve().parents[2]


def test_dataset_example_writes_eyes_and_frames(tmp_path, kernel_cache):
    started = time.monotonic()
    subprocess.run(
        [sys.executable, str(REPO / "tools" / "python_dataset.py"), str(tmp_path / "ds"),
         "--eyes", "2", "--frames", "2", "--size", "160x90", "--cache", str(kernel_cache)],
        check=True,
    )
    seconds = time.monotonic() - started
    manifest = json.loads((tmp_path / "ds" / "manifest.json").read_text())
    assert len(manifest["eyes"]) == 2
    for entry in manifest["eyes"]:
        eye = oc.Eye.load(tmp_path / "ds" / entry["eye_file"])
        # The prescription is a spectacle 12 mm in front of the eye (as `eye estimate --rx`
        # reads it): seen through it, the saved eye is emmetropic.
        c = eye.with_correction(entry["rx"]).refraction(pupil_mm=4.0, wavelength_nm=549.0)
        assert max(abs(c.pupil_m_d), abs(c.pupil_j0_d), abs(c.pupil_j45_d)) < 0.12, (entry["rx"], c)
        assert len(entry["frames"]) == 2
        for frame in entry["frames"]:
            image = oc.read_exr(tmp_path / "ds" / frame["image"])
            assert image.shape == (90, 160, 3)
    assert seconds < 60, f"the example took {seconds:.1f} s"
