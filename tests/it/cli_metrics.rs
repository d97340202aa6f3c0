//! `ocular metrics` end to end (issue 33): HDR-FLIP on EXR pairs and LDR-FLIP on PNG pairs as
//! NVIDIA's reference computes them (the frozen maps of tests/data/flip, nv-flip live), PSNR
//! from its definition, the map file, and one-line exit-2 errors for bad input that leave no
//! file behind.

use crate::common::{json_ok, ocular, ok, temp_dir};
use std::path::Path;
use std::process::Output;

use ocular::image_io::{write_exr_rgba, ImageRgba};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/flip");
const W: usize = 64;
const H: usize = 48;

fn read_f32(name: &str) -> Vec<f32> {
    std::fs::read(format!("{DATA}/{name}"))
        .unwrap()
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

fn exr(path: &Path, rgb: &[f32], (w, h): (usize, usize)) {
    let pixels = rgb
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2], 1.0])
        .collect();
    write_exr_rgba(path, &ImageRgba::new(w as u32, h as u32, pixels)).unwrap();
}

fn png(path: &Path, rgb8: &[u8], (w, h): (usize, usize)) {
    image::save_buffer(path, rgb8, w as u32, h as u32, image::ColorType::Rgb8).unwrap();
}

fn run(args: &[&str]) -> Output {
    ocular().arg("metrics").args(args).output().unwrap()
}

fn oracle_mean(case: &str) -> f64 {
    let text = std::fs::read_to_string(format!("{DATA}/cases.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == case)
        .unwrap()["mean"]
        .as_f64()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn hdr_pair_gets_hdr_flip_as_the_reference_computes_it() {
    let dir = temp_dir("hdr");
    let (r, t, map) = (
        dir.join("ref.exr"),
        dir.join("test.exr"),
        dir.join("flip.png"),
    );
    exr(&r, &read_f32("hdr_ref.f32"), (W, H));
    exr(&t, &read_f32("hdr_test.f32"), (W, H));
    let report = json_ok(&run(&[s(&r), s(&t), "--json", "--map", s(&map)]));
    assert_eq!(report["dynamic_range"], "hdr");
    assert_eq!(report["flip"]["metric"], "HDR-FLIP");
    let mean = report["flip"]["mean"].as_f64().unwrap();
    assert!((mean - oracle_mean("hdr_aces_67")).abs() < 1e-5, "{mean}");
    assert_eq!(report["flip"]["exposures"]["count"], 6);
    let q = |k: &str| report["flip"][k].as_f64().unwrap();
    assert!(
        q("min") <= q("q1")
            && q("q1") <= q("median")
            && q("median") <= q("q3")
            && q("q3") <= q("max")
    );
    // another tone mapper and a given range change the result as the reference's do
    let reinhard = json_ok(&run(&[
        s(&r),
        s(&t),
        "--json",
        "--ppd",
        "30",
        "--tone-mapper",
        "reinhard",
        "--start-exposure",
        "-2",
        "--stop-exposure",
        "3",
        "--exposures",
        "4",
    ]));
    let m = reinhard["flip"]["mean"].as_f64().unwrap();
    assert!((m - oracle_mean("hdr_reinhard_30")).abs() < 1e-5, "{m}");
    // the map: magma, black where the error is least, brightest where it is largest
    let img = image::open(&map).unwrap().into_rgb8();
    assert_eq!((img.width() as usize, img.height() as usize), (W, H));
    let oracle = read_f32("hdr_aces_67_map.f32");
    let arg = |better: fn(f32, f32) -> bool| {
        (0..oracle.len()).fold(0, |b, i| if better(oracle[i], oracle[b]) { i } else { b })
    };
    let (lo, hi) = (arg(|a, b| a < b), arg(|a, b| a > b));
    let bright = |i: usize| {
        img.get_pixel((i % W) as u32, (i / W) as u32)
            .0
            .iter()
            .map(|&v| u32::from(v))
            .sum::<u32>()
    };
    assert!(
        bright(hi) > bright(lo) + 200,
        "{} {}",
        bright(hi),
        bright(lo)
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn png_pair_gets_ldr_flip_psnr_and_ssim() {
    let dir = temp_dir("ldr");
    let (r, t) = (dir.join("ref.png"), dir.join("test.png"));
    let encode = |v: f32| {
        (ocular::metrics::flip::colour::linear_to_srgb(f64::from(v)) * 255.0).round() as u8
    };
    let (ref8, test8): (Vec<u8>, Vec<u8>) = (
        read_f32("ldr_ref.f32").into_iter().map(encode).collect(),
        read_f32("ldr_test.f32").into_iter().map(encode).collect(),
    );
    png(&r, &ref8, (W, H));
    png(&t, &test8, (W, H));
    let oracle = |ppd: f32| {
        let m = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(W as u32, H as u32, &ref8),
            nv_flip::FlipImageRgb8::with_data(W as u32, H as u32, &test8),
            ppd,
        );
        nv_flip::FlipPool::from_image(&m).mean() as f64
    };
    let default = json_ok(&run(&[s(&r), s(&t), "--json"]));
    assert_eq!(default["flip"]["metric"], "LDR-FLIP");
    let mean = default["flip"]["mean"].as_f64().unwrap();
    assert!((mean - oracle(67.020_645)).abs() < 1e-5, "{mean}");
    let at_30 = json_ok(&run(&[s(&r), s(&t), "--json", "--ppd", "30"]))["flip"]["mean"]
        .as_f64()
        .unwrap();
    assert!((at_30 - oracle(30.0)).abs() < 1e-5, "{at_30}");
    // the control: the two viewing distances must be told apart by the bar
    assert!((at_30 - mean).abs() > 1e-3);
    // FLIP's default monitor gives the default ppd
    let monitor = json_ok(&run(&[s(&r), s(&t), "--json", "--monitor", "0.7,3840,0.7"]));
    assert_eq!(monitor["flip"]["mean"], default["flip"]["mean"]);
    // PSNR from its definition on the stored 8-bit values
    let mse = ref8
        .iter()
        .zip(&test8)
        .map(|(a, b)| ((f64::from(*a) - f64::from(*b)) / 255.0).powi(2))
        .sum::<f64>()
        / ref8.len() as f64;
    let psnr = default["psnr_db"].as_f64().unwrap();
    assert!((psnr - 10.0 * (1.0 / mse).log10()).abs() < 1e-4, "{psnr}");
    let mssim = default["mssim"].as_f64().unwrap();
    assert!(mssim > 0.0 && mssim < 1.0);
    // identical images: no error, PSNR null, and the table says ∞
    let same = json_ok(&run(&[s(&r), s(&r), "--json"]));
    assert_eq!(same["flip"]["mean"], 0.0);
    assert!(same["psnr_db"].is_null());
    let table = run(&[s(&r), s(&r)]);
    assert!(table.status.success());
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(
        text.contains("LDR-FLIP") && text.contains('∞') && text.contains("67.02"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// Exit 2, one line on stderr naming what is wrong, and no map written.
fn refused(args: &[&str], map: &Path, expect: &str) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(expect), "{args:?}: {err}");
    assert!(!map.exists(), "{args:?} left a map");
    assert!(out.stdout.is_empty(), "{args:?}");
}

#[test]
fn bad_input_is_refused_with_exit_2() {
    let dir = temp_dir("bad");
    let map = dir.join("map.png");
    let (a, small, nan, black, garbage, p) = (
        dir.join("a.exr"),
        dir.join("small.exr"),
        dir.join("nan.exr"),
        dir.join("black.exr"),
        dir.join("garbage.png"),
        dir.join("a.png"),
    );
    let grey = vec![0.5f32; 8 * 6 * 3];
    exr(&a, &grey, (8, 6));
    exr(&small, &vec![0.5f32; 6 * 6 * 3], (6, 6));
    let mut with_nan = grey.clone();
    with_nan[3 * 9 + 1] = f32::NAN;
    exr(&nan, &with_nan, (8, 6));
    exr(&black, &vec![0.0f32; 8 * 6 * 3], (8, 6));
    std::fs::write(&garbage, b"not a png at all").unwrap();
    png(&p, &[128u8; 8 * 6 * 3], (8, 6));
    let m = s(&map);
    refused(&[s(&a), s(&small), "--map", m], &map, "same size");
    refused(&[s(&a), s(&nan), "--map", m], &map, "x = 1, y = 1");
    refused(&[s(&nan), s(&a), "--map", m], &map, "NaN");
    refused(&[s(&p), s(&garbage), "--map", m], &map, "garbage.png");
    refused(
        &[s(&a), s(&dir.join("missing.exr")), "--map", m],
        &map,
        "missing.exr",
    );
    refused(&[s(&a), s(&p), "--map", m], &map, "one kind");
    refused(&[s(&black), s(&a), "--map", m], &map, "--start-exposure");
    refused(&[s(&a), s(&a), "--ppd", "0", "--map", m], &map, "--ppd");
    refused(&[s(&a), s(&a), "--ppd", "nan", "--map", m], &map, "--ppd");
    refused(
        &[s(&a), s(&a), "--monitor", "0.7,3840", "--map", m],
        &map,
        "WIDTH_M,RES_X,DIST_M",
    );
    refused(
        &[s(&a), s(&a), "--monitor", "0.7,3840,-1", "--map", m],
        &map,
        "DIST_M",
    );
    refused(
        &[s(&p), s(&p), "--tone-mapper", "hable", "--map", m],
        &map,
        "EXR",
    );
    refused(
        &[
            s(&a),
            s(&a),
            "--start-exposure",
            "3",
            "--stop-exposure",
            "1",
            "--map",
            m,
        ],
        &map,
        "start",
    );
    refused(
        &[s(&a), s(&a), "--exposures", "0", "--map", m],
        &map,
        "--exposures",
    );
    refused(
        &[s(&a), s(&a), "--map", s(&dir.join("map.jpg"))],
        &dir.join("map.jpg"),
        ".png",
    );
    refused(&[s(&dir.join("a.tif")), s(&a)], &map, ".exr");
    // the errors ocular raises itself are one line
    let out = run(&[s(&a), s(&small)]);
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim().lines().count(),
        1
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// `compare`'s FLIP column judges the displayed images (linear × 2^EV, clamped) of each row
/// against the truth's at --flip-ppd: a judged file's value is LDR-FLIP of exactly those.
#[test]
fn compare_reports_flip_of_the_displayed_images() {
    use ocular::metrics::flip::{ldr_flip, FlipStats};
    use ocular::metrics::ImageView;
    let dir = temp_dir("compare");
    let (w, h) = (96usize, 54usize);
    let truth: Vec<f32> = (0..w * h * 3)
        .map(|i| {
            let (p, c) = (i / 3, i % 3);
            let (x, y) = ((p % w) as f32, (p / w) as f32);
            0.2 + 0.15 * ((x * 0.3 + c as f32).sin() + (y * 0.2).cos())
                + if (p % w) > 40 { 0.3 } else { 0.0 }
        })
        .collect();
    let judged: Vec<f32> = truth
        .iter()
        .enumerate()
        .map(|(i, v)| v * if (i / 3).is_multiple_of(7) { 1.3 } else { 0.97 })
        .collect();
    let (t, j, report) = (
        dir.join("truth.exr"),
        dir.join("judged.exr"),
        dir.join("c.json"),
    );
    exr(&t, &truth, (w, h));
    exr(&j, &judged, (w, h));
    let cache = dir.join("cache");
    std::fs::create_dir_all(&cache).unwrap();
    let out = ocular()
        .args([
            "compare",
            "--size",
            "96x54",
            "--no-slices",
            "--no-warmup",
            "--flip-ppd",
            "40",
        ])
        .args([
            "--truth-in",
            s(&t),
            "--judge",
            s(&j),
            "--json",
            s(&report),
            "--cache",
            s(&cache),
        ])
        .output()
        .unwrap();
    ok(&out);
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("FLIP"), "{table}");
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(v["flip_ppd"].as_f64(), Some(40.0));
    let ev = v["display_exposure_ev"].as_f64().unwrap() as f32;
    let shown = |rgb: &[f32]| -> Vec<[f32; 4]> {
        let k = ev.exp2();
        rgb.chunks_exact(3)
            .map(|p| {
                [
                    (p[0] * k).clamp(0.0, 1.0),
                    (p[1] * k).clamp(0.0, 1.0),
                    (p[2] * k).clamp(0.0, 1.0),
                    1.0,
                ]
            })
            .collect()
    };
    let (a, b) = (shown(&truth), shown(&judged));
    let expected = |ppd: f64| {
        FlipStats::of(&ldr_flip(
            ImageView::new(w, h, &a),
            ImageView::new(w, h, &b),
            ppd,
        ))
        .mean
    };
    let row = |name: &str| {
        v["methods"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["method"] == name)
            .unwrap()["flip_mean"]
            .as_f64()
            .unwrap()
    };
    assert_eq!(row("reference"), 0.0);
    let got = row("judged");
    assert!(
        (got - expected(40.0)).abs() < 1e-9,
        "{got} against {}",
        expected(40.0)
    );
    // the controls: the default ppd, and the raw linear values instead of the displayed ones
    assert!((got - expected(ocular::metrics::flip::DEFAULT_PPD)).abs() > 1e-4);
    let raw = |rgb: &[f32]| -> Vec<[f32; 4]> {
        rgb.chunks_exact(3)
            .map(|p| [p[0], p[1], p[2], 1.0])
            .collect()
    };
    let (ra, rb) = (raw(&truth), raw(&judged));
    let undisplayed = FlipStats::of(&ldr_flip(
        ImageView::new(w, h, &ra),
        ImageView::new(w, h, &rb),
        40.0,
    ))
    .mean;
    assert!((got - undisplayed).abs() > 1e-4, "{got} {undisplayed}");
    assert!(row("splat") > 0.0 && row("splat") < 1.0);
    // a bad --flip-ppd is refused before any work
    let bad = ocular()
        .args(["compare", "--flip-ppd", "0"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(dir);
}
