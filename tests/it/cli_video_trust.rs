//! A video export can be trusted unattended (issue 20, defects 2, 5, 10 and 13): the folder's
//! manifest refuses a resume with another configuration, a damaged frame is rendered again
//! rather than skipped, splits are byte-identical in both formats, and `--mp4` is checked
//! before any frame is rendered.

use crate::common::{module_cache, ocular, ok, refused, temp_dir};
use std::path::Path;
use std::process::{Command, Output};

/// Four 160×90 frames of a focus sweep; an option in `extra` replaces its default.
fn video(dir: &Path, extra: &[&str]) -> Output {
    let defaults = [
        ("--scene", "primitives"),
        ("--eye", "navarro"),
        ("--size", "160x90"),
        ("--focus-sweep", "0.25..7.5"),
        ("--duration", "0.4"),
        ("--fps", "10"),
    ];
    let mut cmd = ocular();
    cmd.arg("video");
    for (option, value) in defaults {
        if !extra.contains(&option) {
            cmd.args([option, value]);
        }
    }
    cmd.arg("--cache")
        .arg(module_cache())
        .arg("-o")
        .arg(dir)
        .args(extra)
        .output()
        .unwrap()
}

fn frames(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("frame_"))
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect();
    out.sort();
    out
}

#[test]
fn a_resume_with_another_configuration_is_refused() {
    let dir = temp_dir("config");
    ok(&video(&dir, &[]));
    let before = frames(&dir);
    assert_eq!(before.len(), 4);
    assert!(dir.join("ocular-video.json").is_file());

    refused(
        &video(&dir, &["--eye", "myopia"]),
        &["--eye navarro there, myopia here", "--overwrite"],
    );
    refused(
        &video(&dir, &["--size", "192x108"]),
        &["--size 160x90 there, 192x108 here"],
    );
    refused(&video(&dir, &["--fps", "20"]), &["--fps"]);
    refused(&video(&dir, &["--pupil-mm", "3"]), &["--pupil-mm"]);
    refused(
        &video(&dir, &["--layers", "2"]),
        &["--layers 1 there, 2 here"],
    );
    assert_eq!(
        frames(&dir),
        before,
        "a refused run must not touch the frames"
    );

    // The same configuration resumes and skips every (verified) frame.
    let report = ok(&video(&dir, &[]));
    assert!(report.contains("rendered 0, skipped 4"), "{report}");

    // --overwrite replaces the export with the new configuration.
    let report = ok(&video(&dir, &["--eye", "myopia", "--overwrite"]));
    assert!(report.contains("rendered 4"), "{report}");
    let after = frames(&dir);
    assert_eq!(after.len(), 4);
    assert_ne!(
        after, before,
        "the myopic frames differ from the Navarro ones"
    );
    refused(&video(&dir, &[]), &["--eye myopia there, navarro here"]);

    // Two layers: primitives' hidden surfaces show through the blurred edges of the sweep.
    let report = ok(&video(
        &dir,
        &["--eye", "myopia", "--layers", "2", "--overwrite"],
    ));
    assert!(report.contains("rendered 4"), "{report}");
    let layered = frames(&dir);
    assert_eq!(layered.len(), 4);
    assert_ne!(layered, after, "hidden layers change the blurred frames");
    refused(
        &video(&dir, &["--eye", "myopia"]),
        &["--layers 2 there, 1 here"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn damaged_or_unrecorded_frames_are_rendered_again() {
    let dir = temp_dir("damaged");
    ok(&video(&dir, &[]));
    let good = frames(&dir);
    std::fs::write(dir.join("frame_000001.png"), b"").unwrap();
    std::fs::write(dir.join("frame_000002.png"), b"not a png at all").unwrap();
    let mut truncated = good[3].1.clone();
    truncated.truncate(truncated.len() / 2);
    std::fs::write(dir.join("frame_000003.png"), &truncated).unwrap();
    let report = ok(&video(&dir, &[]));
    assert!(report.contains("rendered 3, skipped 1"), "{report}");
    assert_eq!(frames(&dir), good, "re-rendered frames are byte-identical");

    // Frames without a manifest have an unknown configuration: refused.
    let bare = temp_dir("bare");
    std::fs::write(bare.join("frame_000000.png"), &good[0].1).unwrap();
    refused(&video(&bare, &[]), &["no ocular-video.json", "--overwrite"]);
    let report = ok(&video(&bare, &["--overwrite"]));
    assert!(report.contains("rendered 4"), "{report}");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&bare);
}

#[test]
fn exr_splits_are_byte_identical_to_one_run() {
    let whole = temp_dir("exr-whole");
    ok(&video(&whole, &["--format", "exr"]));
    let split = temp_dir("exr-split");
    ok(&video(&split, &["--format", "exr", "--frames", "0..1"]));
    ok(&video(&split, &["--format", "exr", "--frames", "1.."]));
    let (a, b) = (frames(&whole), frames(&split));
    assert_eq!(a.len(), 4);
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(
            x == y,
            "{name}: the split's bytes differ from the whole run's"
        );
    }
    // The digests the jobs recorded are standard SHA-256 of the frames (sha256sum format).
    let sums: String = std::fs::read_dir(split.join("ocular-video.sums"))
        .unwrap()
        .flatten()
        .map(|e| std::fs::read_to_string(e.path()).unwrap())
        .collect();
    assert_eq!(sums.lines().count(), 4, "{sums}");
    assert!(sums
        .lines()
        .all(|l| l.len() == 64 + 2 + "frame_000000.exr".len()));
    let _ = std::fs::remove_dir_all(&whole);
    let _ = std::fs::remove_dir_all(&split);
}

#[test]
fn mp4_without_ffmpeg_fails_before_rendering() {
    let dir = temp_dir("mp4");
    let out = ocular()
        .env("PATH", "/nonexistent")
        .args([
            "video",
            "--scene",
            "primitives",
            "--size",
            "160x90",
            "--mp4",
        ])
        .arg(dir.join("walk.mp4"))
        .arg("-o")
        .arg(dir.join("frames"))
        .output()
        .unwrap();
    refused(&out, &["--mp4", "ffmpeg", "nothing was rendered"]);
    assert!(!dir.join("frames").exists() || frames(&dir.join("frames")).is_empty());
    refused(
        &video(&dir.join("f2"), &["--mp4", "walk.avi"]),
        &["--mp4 walk.avi", ".mp4"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn side_by_side_errors_name_their_own_option() {
    let dir = temp_dir("sbs");
    refused(
        &video(&dir, &["--side-by-side", "hyperopia"]),
        &["--side-by-side"],
    );
    let err =
        String::from_utf8_lossy(&video(&dir, &["--side-by-side", "hyperopia"]).stderr).into_owned();
    assert!(!err.contains("--eye"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn only_dead_jobs_temporaries_are_removed() {
    let dir = temp_dir("temporaries");
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .unwrap()
        .trim()
        .replace(|c: char| !c.is_ascii_alphanumeric() && c != '-', "_");
    let mut child = Command::new("true").spawn().unwrap();
    let dead = child.id();
    child.wait().unwrap();
    let ours_dead = format!("frame_000002.png.tmp-{host}-{dead}");
    let ours_live = format!("frame_000003.png.tmp-{host}-{}", std::process::id());
    let elsewhere = "frame_000001.png.tmp-another-machine-4242".to_string();
    for name in [&ours_dead, &ours_live, &elsewhere] {
        std::fs::write(dir.join(name), b"partial").unwrap();
    }
    ok(&video(&dir, &[]));
    assert!(
        !dir.join(&ours_dead).exists(),
        "a dead job's temporary stays"
    );
    // A split job still writing (here, or on another machine sharing the folder) keeps its
    // temporary: removing it would make its rename fail.
    assert!(dir.join(&ours_live).exists());
    assert!(dir.join(&elsewhere).exists());
    let _ = std::fs::remove_dir_all(&dir);
}
