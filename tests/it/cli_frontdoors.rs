//! The front doors end to end on lavapipe with tiny frames: `render`, `video` (resume after a
//! kill, byte-identical splits, bad ranges), `bench` (JSON a script can read) and `compare`.

use crate::common::{module_cache, ocular, temp_dir};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The row of `compare --json`'s report for one method (or judged file).
fn method_row(report: &serde_json::Value, name: &str) -> serde_json::Value {
    report["methods"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["method"] == name)
        .unwrap_or_else(|| panic!("no row {name}: {report}"))
        .clone()
}

fn run_ok(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{:?} failed:\n{}",
        cmd,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn png_size(path: &Path) -> (u32, u32) {
    let decoder = image::ImageReader::open(path)
        .unwrap()
        .with_guessed_format()
        .unwrap();
    let img = decoder
        .decode()
        .unwrap_or_else(|e| panic!("{} does not decode: {e}", path.display()));
    (img.width(), img.height())
}

#[test]
fn render_writes_the_picture_and_reports_json() {
    let dir = temp_dir("render");
    let out = dir.join("frame.png");
    let json = run_ok(
        ocular()
            .args([
                "render", "--size", "160x90", "--eye", "navarro", "--json", "--cache",
            ])
            .arg(module_cache())
            .arg("-o")
            .arg(&out),
    );
    assert_eq!(png_size(&out), (160, 90));
    let summary: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(summary["method"], "splat");
    assert!(
        (summary["focus_d"].as_f64().unwrap() - 1.0 / 7.5).abs() < 1e-9,
        "primitives focuses at 7.5 m"
    );
    let pupil = summary["pupil_mm"].as_f64().unwrap();
    assert!((1.5..=8.0).contains(&pupil), "{pupil}");
    assert!(summary["gpu_total_ms"].as_f64().unwrap() > 0.0);

    // EXR output is linear and finite.
    let exr = dir.join("frame.exr");
    run_ok(
        ocular()
            .args([
                "render",
                "--size",
                "160x90",
                "--eye",
                "navarro",
                "--focus-at",
                "80,45",
                "--pupil-mm",
                "4",
                "--cache",
            ])
            .arg(module_cache())
            .arg("-o")
            .arg(&exr),
    );
    let image = ocular::image_io::read_exr_rgba(&exr).unwrap();
    assert!(image.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));
}

#[test]
fn render_refuses_bad_input_with_exit_2_and_no_file() {
    let dir = temp_dir("render-bad");
    let out = dir.join("x.png");
    let cases: [&[&str]; 6] = [
        &["--focus-m", "-1"],
        &["--eye", "no-such-eye"],
        &["--pupil-mm", "12"],
        &["--focus-at", "5000,1"],
        &["--tile-size", "12"],
        &["--scene", "no-such-scene"],
    ];
    for case in cases {
        let output = ocular()
            .args(["render", "--size", "64x36"])
            .args(case)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{case:?}: {stderr}");
        assert!(
            stderr.starts_with("error:") && stderr.trim().lines().count() == 1,
            "{case:?}: {stderr}"
        );
        assert!(!out.exists(), "{case:?} wrote a file");
    }
    let output = ocular()
        .args(["render", "-o"])
        .arg(dir.join("x.bmp"))
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
}

fn video(dir: &Path, extra: &[&str]) -> Command {
    let mut cmd = ocular();
    cmd.args([
        "video",
        "--scene",
        "primitives",
        "--eye",
        "navarro",
        "--size",
        "160x90",
        "--focus-sweep",
        "0.25..7.5",
        "--duration",
        "1",
        "--fps",
        "10",
        "--cache",
    ])
    .arg(module_cache())
    .arg("-o")
    .arg(dir)
    .args(extra);
    cmd
}

fn frames_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("frame_"))
        .collect();
    names.sort();
    names
}

#[test]
fn video_resumes_after_a_kill_and_splits_identically() {
    // One run of all ten frames.
    let whole = temp_dir("video-whole");
    run_ok(&mut video(&whole, &[]));
    let names = frames_in(&whole);
    assert_eq!(names.len(), 10, "{names:?}");
    assert!(names
        .iter()
        .all(|n| n.ends_with(".png") && !n.contains(".tmp-")));

    // The same frames in two jobs give byte-identical files.
    let split = temp_dir("video-split");
    run_ok(&mut video(&split, &["--frames", "0..4"]));
    run_ok(&mut video(&split, &["--frames", "4.."]));
    for name in &names {
        assert_eq!(
            std::fs::read(whole.join(name)).unwrap(),
            std::fs::read(split.join(name)).unwrap(),
            "{name} differs"
        );
    }

    // Kill a run part-way; complete frames stay, the rerun adds only the missing ones.
    let resumed = temp_dir("video-resume");
    let mut child = video(&resumed, &[])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while frames_in(&resumed)
        .iter()
        .filter(|n| n.ends_with(".png"))
        .count()
        < 3
        && started.elapsed() < Duration::from_secs(300)
    {
        std::thread::sleep(Duration::from_millis(50));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done_before: Vec<String> = frames_in(&resumed)
        .into_iter()
        .filter(|n| n.ends_with(".png"))
        .collect();
    assert!(!done_before.is_empty());
    for name in &done_before {
        // Every file with a final name is a complete frame.
        assert_eq!(png_size(&resumed.join(name)), (160, 90));
    }
    let modified: Vec<_> = done_before
        .iter()
        .map(|n| {
            std::fs::metadata(resumed.join(n))
                .unwrap()
                .modified()
                .unwrap()
        })
        .collect();
    let report = run_ok(&mut video(&resumed, &[]));
    assert!(
        report.contains(&format!("skipped {}", done_before.len())),
        "{report}"
    );
    assert_eq!(frames_in(&resumed), names, "no temporaries may remain");
    for (name, before) in done_before.iter().zip(modified) {
        assert_eq!(
            std::fs::metadata(resumed.join(name))
                .unwrap()
                .modified()
                .unwrap(),
            before,
            "{name} was rewritten"
        );
        assert_eq!(
            std::fs::read(whole.join(name)).unwrap(),
            std::fs::read(resumed.join(name)).unwrap()
        );
    }
}

#[test]
fn video_refuses_bad_ranges_and_unwritable_folders() {
    let dir = temp_dir("video-bad");
    for range in ["5..3", "0..11", "x..2"] {
        let out = video(&dir, &["--frames", range]).output().unwrap();
        assert_eq!(
            out.status.code(),
            Some(2),
            "{range}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stderr).contains("--frames"));
    }
    let file = dir.join("not-a-folder");
    std::fs::write(&file, b"x").unwrap();
    let out = video(&file, &[]).output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(frames_in(&dir).is_empty());
}

#[test]
fn bench_reports_every_pass_and_totals_that_add_up() {
    let dir = temp_dir("bench");
    let json = dir.join("bench.json");
    run_ok(
        ocular()
            .args([
                "bench", "--size", "160x90", "--eye", "navarro", "--warmup", "1", "--frames", "3",
                "--cache",
            ])
            .arg(module_cache())
            .arg("--json")
            .arg(&json),
    );
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let passes = report["passes"].as_array().unwrap();
    let names: Vec<&str> = passes.iter().map(|p| p["name"].as_str().unwrap()).collect();
    // Steady-state frames keep the PSF texture (the eye's state does not change), and draw
    // the scene in splat's own submission: no frame is uploaded.
    assert!(!names.contains(&"psf texture"), "{names:?}");
    assert!(!names.contains(&"upload"), "{names:?}");
    // per frame only the object radii (32 bytes per distance), the field table and the
    // uniforms: a few KiB, where the frame's pixels would be 160 × 90 × 20 bytes
    assert!(
        report["counters"]["upload_bytes"].as_u64().unwrap() < 8192,
        "{}",
        report["counters"]
    );
    assert_eq!(
        report["counters"]["submissions"], 1,
        "{}",
        report["counters"]
    );
    assert_eq!(
        report["counters"]["allocations"], 0,
        "{}",
        report["counters"]
    );
    for want in [
        "raster",
        "resolve",
        "input",
        "fragments",
        "tile count",
        "prefix sum",
        "tile fill",
        "tile sort",
        "convolve",
    ] {
        assert!(names.contains(&want), "{want} missing from {names:?}");
    }
    // The total of each frame is the sum of its passes, so the means add up exactly.
    let sum: f64 = passes.iter().map(|p| p["mean_ms"].as_f64().unwrap()).sum();
    let total = report["total"]["mean_ms"].as_f64().unwrap();
    assert!(
        (sum - total).abs() <= 1e-6 * total.max(1.0),
        "{sum} vs {total}"
    );
    for p in passes {
        let (mean, median, p95) = (
            p["mean_ms"].as_f64().unwrap(),
            p["median_ms"].as_f64().unwrap(),
            p["p95_ms"].as_f64().unwrap(),
        );
        assert!(mean >= 0.0 && median >= 0.0 && p95 >= median, "{p}");
    }
    assert_eq!(report["frames"], 3);
    assert!(report["device"].as_str().is_some_and(|d| !d.is_empty()));
    // the host's share is reported apart: per frame, wall minus GPU time, so the means add up
    let host = report["host_ms_per_frame"]["mean_ms"].as_f64().unwrap();
    let wall = report["wall_ms_per_frame"]["mean_ms"].as_f64().unwrap();
    assert!(
        (host + total - wall).abs() <= 1e-6 * wall.max(1.0),
        "{host} + {total} vs {wall}"
    );
    // it holds the frame's read-back, at least the 160 × 90 × 16 bytes of colour
    assert!(host > 0.0, "{host}");
}

/// A peeled scene (`--layers 2`) stays on the GPU in bench and render: bench's steady frame
/// is one submission, no allocation, no pixel up and only the image down, where its baseline
/// (every layer read back, its depth uploaded for the next peel, the layers uploaded to
/// splat) moves every layer both ways; render draws the layers in splat's submission (its
/// passes have the raster and the input pass, no upload).
#[test]
fn peeled_layers_stay_on_the_gpu_in_bench_and_render() {
    let dir = temp_dir("layers");
    let json = dir.join("bench.json");
    run_ok(
        ocular()
            .args([
                "bench",
                "--size",
                "160x90",
                "--eye",
                "navarro",
                "--layers",
                "2",
                "--warmup",
                "1",
                "--frames",
                "2",
                "--baseline",
                "--cache",
            ])
            .arg(module_cache())
            .arg("--json")
            .arg(&json),
    );
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(report["layers"], 2);
    let (c, old) = (&report["counters"], &report["baseline"]["counters"]);
    let layer_bytes = 2 * 160 * 90 * 20;
    assert_eq!(c["submissions"], 1, "{c}");
    assert_eq!(c["allocations"], 0, "{c}");
    assert!(c["upload_bytes"].as_u64().unwrap() < 8192, "{c}");
    // the image and the band table's header
    assert_eq!(c["readback_bytes"], 160 * 90 * 16 + 32, "{c}");
    assert!(old["upload_bytes"].as_u64().unwrap() > layer_bytes, "{old}");
    assert!(
        old["readback_bytes"].as_u64().unwrap() > layer_bytes,
        "{old}"
    );
    assert!(old["submissions"].as_u64().unwrap() >= 4, "{old}");

    let summary: serde_json::Value = serde_json::from_str(&run_ok(
        ocular()
            .args([
                "render", "--size", "160x90", "--eye", "navarro", "--layers", "2", "--json",
                "--cache",
            ])
            .arg(module_cache())
            .arg("-o")
            .arg(dir.join("layers.png")),
    ))
    .unwrap();
    let passes: Vec<&str> = summary["gpu_ms"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p[0].as_str().unwrap())
        .collect();
    assert!(
        passes.contains(&"raster") && passes.contains(&"input") && !passes.contains(&"upload"),
        "{passes:?}"
    );
}

#[test]
fn compare_reports_quality_and_writes_maps() {
    let dir = temp_dir("compare");
    let json = dir.join("compare.json");
    run_ok(
        ocular()
            .args(["compare", "--size", "128x72", "--eye", "navarro", "--cache"])
            .arg(module_cache())
            .arg("--json")
            .arg(&json)
            .arg("--maps")
            .arg(dir.join("maps")),
    );
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let method = |name: &str| method_row(&report, name);
    // At this size the blur is a pixel or two, where every method is close to the truth; the
    // ranking under strong blur is asserted in slices.rs.
    let (truth, splat, slices) = (method("reference"), method("splat"), method("slices"));
    assert!(
        truth["psnr_db"].is_null(),
        "the truth against itself is identical: {truth}"
    );
    assert_eq!(truth["mssim"].as_f64(), Some(1.0));
    assert!(splat["mssim"].as_f64().unwrap() >= 0.99, "{splat}");
    for m in [&splat, &slices] {
        let db = m["psnr_db"].as_f64().unwrap_or(f64::INFINITY);
        assert!(db > 30.0, "{m}");
        assert!(
            m["seconds"].as_f64().unwrap() > 0.0
                && m["speedup_vs_reference"].as_f64().unwrap() > 0.0
        );
    }
    for f in [
        "truth.png",
        "splat.png",
        "slices.png",
        "ssim_splat.png",
        "ssim_slices.png",
    ] {
        assert_eq!(png_size(&dir.join("maps").join(f)), (128, 72), "{f}");
    }
}

/// `--judge` measures a saved image exactly as the methods are measured, and `--truth-bin-d`
/// changes the reference: the default truth saved and judged again is identical to the bit,
/// a truth rounded to 0.1 D bins is not. `--no-warmup` times splat's first frame, which is
/// the same image as the second.
#[test]
fn compare_judges_saved_images_and_coarse_truths() {
    let dir = temp_dir("judge");
    let (fine, coarse) = (dir.join("fine.exr"), dir.join("coarse.exr"));
    let (json, warm_json) = (dir.join("judge.json"), dir.join("warm.json"));
    let common = ["compare", "--size", "96x54", "--no-slices", "--cache"];
    let run = |extra: &[&std::ffi::OsStr]| {
        run_ok(ocular().args(common).arg(module_cache()).args(extra));
    };
    run(&[
        "--truth-out".as_ref(),
        fine.as_os_str(),
        "--json".as_ref(),
        warm_json.as_os_str(),
    ]);
    run(&[
        "--truth-bin-d".as_ref(),
        "0.1".as_ref(),
        "--truth-out".as_ref(),
        coarse.as_os_str(),
    ]);
    run(&[
        "--judge".as_ref(),
        fine.as_os_str(),
        "--judge".as_ref(),
        coarse.as_os_str(),
        "--json".as_ref(),
        json.as_os_str(),
        "--no-warmup".as_ref(),
    ]);
    let read = |path: &Path| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
    };
    let (report, warm) = (read(&json), read(&warm_json));
    assert_eq!(report["truth_bin_d"].as_f64(), Some(0.001));
    assert_eq!(report["splat_warmed_up"], false);
    assert_eq!(warm["splat_warmed_up"], true);
    let splat_db = |r: &serde_json::Value| method_row(r, "splat")["psnr_db"].as_f64();
    assert!(splat_db(&warm).is_some_and(f64::is_finite), "{warm}");
    assert_eq!(
        splat_db(&report),
        splat_db(&warm),
        "the first splat frame must be the second's image"
    );
    let row = |name: &str| method_row(&report, name);
    assert!(row("fine")["psnr_db"].is_null(), "{}", row("fine"));
    let coarse_db = row("coarse")["psnr_db"].as_f64();
    assert!(
        coarse_db.is_some_and(f64::is_finite),
        "0.1 D bins must change the truth: {}",
        row("coarse")
    );
    assert!(
        row("coarse")["seconds"].is_null(),
        "a judged file has no time"
    );
}

/// `render --scene FILE` without `--size` renders at the scene's `[camera] resolution`, as
/// scenes/README.md promises (it used to render 640×360 whatever the file said).
#[test]
fn render_uses_the_scene_resolution() {
    let dir = temp_dir("scene-resolution");
    let scene = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/primitives.toml"),
    )
    .unwrap()
    .replace("resolution = [1280, 720]", "resolution = [72, 40]");
    assert!(scene.contains("[72, 40]"));
    let scene_path = dir.join("tiny.toml");
    std::fs::write(&scene_path, scene).unwrap();
    let out = dir.join("frame.png");
    run_ok(
        ocular()
            .arg("render")
            .arg("--scene")
            .arg(&scene_path)
            .args(["--eye", "navarro", "--cache"])
            .arg(module_cache())
            .arg("-o")
            .arg(&out),
    );
    assert_eq!(png_size(&out), (72, 40));
}

#[test]
fn bench_refuses_a_sample_count_the_draw_cannot_take() {
    for bad in ["3", "1", "x"] {
        let out = ocular()
            .args(["bench", "--draw-samples", bad])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
        assert!(
            err.contains("--draw-samples") && err.contains("2, 4 or 8"),
            "{err}"
        );
    }
}
