//! FLIP (issue 33) against NVIDIA's reference implementation and against closed forms written
//! here: the reference's maps for synthetic LDR and HDR pairs (frozen by tools/flip_oracle.py
//! from the `flip-evaluator` package, and live through the `nv-flip` bindings on 8-bit
//! images), the CSF filters' response to sinusoids, the edge detector's response to a step,
//! CIELAB of the sRGB primaries, and HDR-FLIP's exposure range. Each comparison has a negative
//! control (a shifted map, a wrong ppd) that must fail the same bar.

use ocular::metrics::flip::{
    self, colour, csf, features, hdr_flip, ldr_flip, FlipStats, HdrSettings, Plane, ToneMapper,
    DEFAULT_PPD,
};
use ocular::metrics::ImageView;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/flip");

fn read_f32(name: &str) -> Vec<f32> {
    let bytes = std::fs::read(format!("{DATA}/{name}")).expect("oracle data");
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

fn rgba(rgb: &[f32]) -> Vec<[f32; 4]> {
    rgb.chunks_exact(3)
        .map(|p| [p[0], p[1], p[2], 1.0])
        .collect()
}

/// Largest and mean absolute difference of two maps.
fn differences(a: &[f32], b: &[f32]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let d: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(x, y)| (f64::from(*x) - f64::from(*y)).abs())
        .collect();
    (
        d.iter().copied().fold(0.0, f64::max),
        d.iter().sum::<f64>() / d.len() as f64,
    )
}

/// The map shifted right by one pixel (the first column repeated): a negative control.
fn shifted(map: &[f32], w: usize) -> Vec<f32> {
    map.chunks_exact(w)
        .flat_map(|row| std::iter::once(row[0]).chain(row[..w - 1].iter().copied()))
        .collect()
}

// The reference computes in f32, ours in f64: the maps agree to about 3e-5 per pixel (printed
// by the tests), so these bars hold a few times that.
const MAP_MAX_DIFF: f64 = 2e-4;
const MAP_MEAN_DIFF: f64 = 2e-5;
const MEAN_DIFF: f64 = 1e-5;

struct Case {
    name: String,
    width: usize,
    height: usize,
    hdr: bool,
    ppd: f64,
    mean: f64,
    reference: Vec<[f32; 4]>,
    test: Vec<[f32; 4]>,
    map: Vec<f32>,
    settings: HdrSettings,
    range: Option<(f64, f64, usize)>,
}

fn cases() -> Vec<Case> {
    let text = std::fs::read_to_string(format!("{DATA}/cases.json")).expect("cases.json");
    let json: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    json["cases"]
        .as_array()
        .expect("cases")
        .iter()
        .map(|c| {
            let hdr = c["mode"] == "HDR";
            let tone_mapper = match c["tone_mapper"].as_str() {
                Some("hable") => ToneMapper::Hable,
                Some("reinhard") => ToneMapper::Reinhard,
                _ => ToneMapper::Aces,
            };
            let given = c["range_given"].as_bool().unwrap_or(false);
            let range = hdr.then(|| {
                (
                    c["start"].as_f64().unwrap(),
                    c["stop"].as_f64().unwrap(),
                    c["count"].as_u64().unwrap() as usize,
                )
            });
            Case {
                name: c["name"].as_str().unwrap().to_string(),
                width: c["width"].as_u64().unwrap() as usize,
                height: c["height"].as_u64().unwrap() as usize,
                hdr,
                ppd: c["ppd"].as_f64().unwrap(),
                mean: c["mean"].as_f64().unwrap(),
                reference: rgba(&read_f32(c["reference"].as_str().unwrap())),
                test: rgba(&read_f32(c["test"].as_str().unwrap())),
                map: read_f32(c["map"].as_str().unwrap()),
                settings: HdrSettings {
                    tone_mapper,
                    start: given.then(|| range.unwrap().0),
                    stop: given.then(|| range.unwrap().1),
                    count: given.then(|| range.unwrap().2),
                },
                range,
            }
        })
        .collect()
}

fn ours(case: &Case, ppd: f64) -> Vec<f32> {
    let r = ImageView::new(case.width, case.height, &case.reference);
    let t = ImageView::new(case.width, case.height, &case.test);
    if case.hdr {
        hdr_flip(r, t, ppd, &case.settings).expect("HDR-FLIP").map
    } else {
        ldr_flip(r, t, ppd)
    }
}

#[test]
fn maps_match_the_reference_implementation_on_float_images() {
    let all = cases();
    assert_eq!(all.len(), 5);
    for case in &all {
        let map = ours(case, case.ppd);
        let (max_diff, mean_diff) = differences(&map, &case.map);
        let mean = FlipStats::of(&map).mean;
        println!(
            "{}: mean {mean:.6} (reference {:.6}), map differs by at most {max_diff:.2e} (mean {mean_diff:.2e})",
            case.name, case.mean
        );
        assert!(max_diff < MAP_MAX_DIFF, "{}: {max_diff}", case.name);
        assert!(mean_diff < MAP_MEAN_DIFF, "{}: {mean_diff}", case.name);
        assert!((mean - case.mean).abs() < MEAN_DIFF, "{}", case.name);
        // the map must be informative: not flat, so the shifted control below means something
        assert!(FlipStats::of(&case.map).max > 0.3, "{}", case.name);

        // negative controls: the reference's map one pixel to the side, our map at a wrong ppd
        let (shift_max, shift_mean) = differences(&map, &shifted(&case.map, case.width));
        assert!(
            shift_max > MAP_MAX_DIFF && shift_mean > MAP_MEAN_DIFF,
            "{}: a shifted map passes ({shift_max}, {shift_mean})",
            case.name
        );
        let wrong = ours(case, case.ppd * 0.75);
        let (wrong_max, wrong_mean) = differences(&wrong, &case.map);
        assert!(
            wrong_max > MAP_MAX_DIFF && wrong_mean > MAP_MEAN_DIFF,
            "{}: a wrong ppd passes ({wrong_max}, {wrong_mean})",
            case.name
        );
    }
}

#[test]
fn hdr_exposure_range_matches_the_reference_implementation() {
    for case in cases().iter().filter(|c| c.hdr) {
        let r = ImageView::new(case.width, case.height, &case.reference);
        let got = flip::exposure_range(r, &case.settings).expect("range");
        let (start, stop, count) = case.range.unwrap();
        assert!((got.start - start).abs() < 1e-4, "{}: {got:?}", case.name);
        assert!((got.stop - stop).abs() < 1e-4, "{}: {got:?}", case.name);
        assert_eq!(got.count, count, "{}", case.name);
    }
}

/// The exposure range from its definition: the input the tone curve maps to 0.85, found by
/// bisection on the curve itself, over the brightest and the (upper) median luminance.
#[test]
fn hdr_exposure_range_follows_its_definition() {
    // luminances 0.5, 1, 2, 4, 8 (grey pixels): median 2, max 8
    let pixels: Vec<[f32; 4]> = [0.5f32, 1.0, 2.0, 4.0, 8.0]
        .iter()
        .map(|&v| [v, v, v, 1.0])
        .collect();
    let view = ImageView::new(5, 1, &pixels);
    for tm in [ToneMapper::Aces, ToneMapper::Hable, ToneMapper::Reinhard] {
        let (mut lo, mut hi) = (0.0f64, 100.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if tm.apply([mid; 3])[1] < 0.85 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let x = 0.5 * (lo + hi);
        let range = flip::exposure_range(
            view,
            &HdrSettings {
                tone_mapper: tm,
                ..HdrSettings::default()
            },
        )
        .unwrap();
        assert!((range.start - (x / 8.0).log2()).abs() < 1e-9, "{tm:?}");
        assert!((range.stop - (x / 2.0).log2()).abs() < 1e-9, "{tm:?}");
        // two stops apart: max(2, ceil(2)) exposures
        assert_eq!(range.count, 2);
        // the control: the lower median (1) would move the stop by a whole stop
        assert!((range.stop - (x / 1.0).log2()).abs() > 0.5);
    }
    // an all-black reference has no automatic range: an error, not an infinite loop
    let black = vec![[0.0f32, 0.0, 0.0, 1.0]; 4];
    assert!(flip::exposure_range(ImageView::new(2, 2, &black), &HdrSettings::default()).is_err());
}

/// 8-bit sRGB test patterns: edges, fine text-like detail, noise, a colour change.
fn patterns(w: usize, h: usize) -> Vec<(&'static str, Vec<u8>, Vec<u8>)> {
    let mut state = 12345u64;
    let mut rand = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 33) as f64 / (1u64 << 31) as f64
    };
    let make = |f: &mut dyn FnMut(usize, usize, usize) -> f64| -> Vec<u8> {
        let mut out = Vec::with_capacity(w * h * 3);
        for y in 0..h {
            for x in 0..w {
                for c in 0..3 {
                    out.push((f(x, y, c).clamp(0.0, 1.0) * 255.0).round() as u8);
                }
            }
        }
        out
    };
    let bars = |x: usize, y: usize, c: usize| -> f64 {
        let stripe = if (x / 3 + y / 5).is_multiple_of(2) {
            0.85
        } else {
            0.15
        };
        stripe * [1.0, 0.7, 0.4][c] + 0.1 * (x as f64 / w as f64)
    };
    let reference = make(&mut |x, y, c| bars(x, y, c));
    let noisy = make(&mut |x, y, c| bars(x, y, c) + 0.12 * (rand() - 0.5));
    let blurred = make(&mut |x, y, c| {
        0.5 * bars(x, y, c)
            + 0.25 * (bars(x.saturating_sub(1), y, c) + bars((x + 1).min(w - 1), y, c))
    });
    let tinted = make(&mut |x, y, c| bars(x, y, c) * [0.8, 1.0, 1.2][c]);
    vec![
        ("noise", reference.clone(), noisy),
        ("blur", reference.clone(), blurred),
        ("tint", reference, tinted),
    ]
}

fn decode(srgb8: &[u8]) -> Vec<[f32; 4]> {
    srgb8
        .chunks_exact(3)
        .map(|p| {
            let l = |v: u8| colour::srgb_to_linear(f64::from(v) / 255.0) as f32;
            [l(p[0]), l(p[1]), l(p[2]), 1.0]
        })
        .collect()
}

#[test]
fn ldr_maps_match_nv_flip_on_8bit_images() {
    let (w, h) = (72, 40);
    for (name, reference, test) in patterns(w, h) {
        let oracle = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(w as u32, h as u32, &reference),
            nv_flip::FlipImageRgb8::with_data(w as u32, h as u32, &test),
            DEFAULT_PPD as f32,
        )
        .to_vec();
        let (r, t) = (decode(&reference), decode(&test));
        let ours_at = |ppd: f64| ldr_flip(ImageView::new(w, h, &r), ImageView::new(w, h, &t), ppd);
        let map = ours_at(DEFAULT_PPD);
        let (max_diff, mean_diff) = differences(&map, &oracle);
        let (ours_mean, oracle_mean) = (FlipStats::of(&map).mean, FlipStats::of(&oracle).mean);
        println!("{name}: mean {ours_mean:.6} (nv-flip {oracle_mean:.6}), map differs by at most {max_diff:.2e}");
        assert!(
            max_diff < MAP_MAX_DIFF && mean_diff < MAP_MEAN_DIFF,
            "{name}"
        );
        assert!((ours_mean - oracle_mean).abs() < MEAN_DIFF, "{name}");
        assert!(oracle_mean > 0.02, "{name}: the pattern must show an error");
        let (s_max, s_mean) = differences(&map, &shifted(&oracle, w));
        assert!(
            s_max > MAP_MAX_DIFF && s_mean > MAP_MEAN_DIFF,
            "{name}: shifted map passes"
        );
        let (p_max, p_mean) = differences(&ours_at(DEFAULT_PPD * 1.5), &oracle);
        assert!(
            p_max > MAP_MAX_DIFF && p_mean > MAP_MEAN_DIFF,
            "{name}: wrong ppd passes"
        );
    }
}

#[test]
fn identical_images_have_zero_error_and_default_ppd_is_flips() {
    let (w, h) = (72, 40);
    let (_, reference, _) = patterns(w, h).remove(0);
    let r = decode(&reference);
    let map = ldr_flip(
        ImageView::new(w, h, &r),
        ImageView::new(w, h, &r),
        DEFAULT_PPD,
    );
    assert!(map.iter().all(|&v| v == 0.0));
    // 0.7 m from a 0.7 m wide, 3840-pixel monitor: 3840 π / 180
    assert!((DEFAULT_PPD - 67.020643).abs() < 1e-6);
    assert!((flip::pixels_per_degree(0.7, 3840.0, 0.7) - DEFAULT_PPD).abs() < 1e-12);
}

/// The 2-D CSF kernel Σ a_i √(π/b_i) exp(−π² r² / b_i) has the 2-D Fourier transform
/// Σ a_i √(b_i/π) exp(−b_i ρ²); normalised at ρ = 0, that is the gain on a grating of ρ cycles
/// per degree. The grating is filtered and its amplitude measured away from the borders.
#[test]
fn csf_filters_pass_a_sinusoid_with_the_closed_form_gain() {
    let ppd = DEFAULT_PPD;
    let gain = |channel: usize, f: f64| {
        let g = csf::CSF[channel];
        let terms = [(g.a1, g.b1), (g.a2, g.b2)];
        let at = |f: f64| -> f64 {
            terms
                .iter()
                .map(|(a, b)| a * (b / std::f64::consts::PI).sqrt() * (-b * f * f).exp())
                .sum()
        };
        at(f) / at(0.0)
    };
    let (w, h) = (256, 8);
    let measure = |channel: usize, f: f64, filter_ppd: f64| {
        let omega = 2.0 * std::f64::consts::PI * f / ppd;
        let plane = Plane::new(
            w,
            h,
            (0..w * h).map(|i| (omega * (i % w) as f64).cos()).collect(),
        );
        let out = csf::filter_channel(&plane, channel, filter_ppd);
        // the kernel is even, so the output is gain · cos: least squares over the middle row,
        // away from the clamped borders
        let y = h / 2;
        let (mut num, mut den) = (0.0, 0.0);
        for x in 40..w - 40 {
            let c = (omega * x as f64).cos();
            num += out.at(x, y) * c;
            den += c * c;
        }
        num / den
    };
    for channel in 0..3 {
        for f in [1.0, 4.0, 8.0, 12.0, 20.0] {
            let expected = gain(channel, f);
            let got = measure(channel, f, ppd);
            assert!(
                (got - expected).abs() < 5e-3,
                "channel {channel}, {f} cpd: gain {got} against {expected}"
            );
        }
        // the control: a filter built for another viewing distance misses the bar
        let wrong = measure(channel, 8.0, ppd * 0.75);
        assert!(
            (wrong - gain(channel, 8.0)).abs() > 5e-3,
            "channel {channel}"
        );
    }
}

/// A luminance step of height Δ between columns m0 − 1 and m0: the balanced first-derivative
/// detector answers Δ on both sides of the step and, m pixels further, Δ times the Gaussian
/// tail beyond it, exp(−m (m + 1) / 2σ²) by the midpoint rule for Σ k exp(−k² / 2σ²).
#[test]
fn edge_detector_answers_a_step_with_its_height() {
    let ppd = DEFAULT_PPD;
    let sigma = features::sigma_px(ppd);
    let (w, h, m0, delta) = (64, 9, 32, 0.6);
    let step = |x: usize| if x < m0 { 0.2 } else { 0.2 + delta };
    let plane = Plane::new(w, h, (0..w * h).map(|i| step(i % w)).collect());
    let detect = |ppd: f64| features::detect(&plane, &features::FeatureTaps::new(ppd));
    let found = detect(ppd);
    let y = h / 2;
    assert!((found.edges.at(m0, y) - delta).abs() < 1e-12);
    assert!((found.edges.at(m0 - 1, y) - delta).abs() < 1e-12);
    for m in 1..6 {
        let expected = delta * (-((m * (m + 1)) as f64) / (2.0 * sigma * sigma)).exp();
        let got = found.edges.at(m0 + m, y);
        assert!(
            (got - expected).abs() < 0.02 * delta,
            "{m} px from the edge: {got} against {expected}"
        );
    }
    // far from the step (beyond the kernel) nothing is detected
    assert!(found.edges.at(2, y).abs() < 1e-12 && found.points.at(2, y).abs() < 1e-12);
    // the control: a detector for a wrong ppd has another reach
    let wrong = detect(ppd * 0.75);
    let m = 3;
    let expected = delta * (-((m * (m + 1)) as f64) / (2.0 * sigma * sigma)).exp();
    assert!((wrong.edges.at(m0 + m as usize, y) - expected).abs() > 0.02 * delta);
    // a step in one image and none in the other: ΔE_f = (Δ / √2)^½ at the step
    let flat = Plane::new(w, h, vec![0.2; w * h]);
    let taps = features::FeatureTaps::new(ppd);
    let diff = features::feature_difference(&found, &features::detect(&flat, &taps));
    let at_step = diff[y * w + m0];
    assert!((at_step - (delta / std::f64::consts::SQRT_2).sqrt()).abs() < 1e-12);
}

/// CIELAB of the sRGB primaries and white as published (e.g. Lindbloom's calculator, D65):
/// green (87.737, −86.185, 83.181), blue (32.303, 79.197, −107.864), white (100, 0, 0).
#[test]
fn colour_pipeline_reproduces_published_lab_values() {
    let lab = |rgb: [f64; 3]| colour::xyz_to_lab(colour::linear_rgb_to_xyz(rgb));
    let close = |a: [f64; 3], b: [f64; 3], tol: f64| (0..3).all(|i| (a[i] - b[i]).abs() < tol);
    assert!(close(lab([0.0, 1.0, 0.0]), [87.737, -86.185, 83.181], 0.01));
    assert!(close(
        lab([0.0, 0.0, 1.0]),
        [32.303, 79.197, -107.864],
        0.01
    ));
    assert!(close(lab([1.0, 1.0, 1.0]), [100.0, 0.0, 0.0], 1e-9));
    // the largest error from those values: HyAB of Hunt-adjusted green and blue, to the 0.7
    let (g, b) = ([87.737, -86.185, 83.181], [32.303, 79.197, -107.864]);
    let hunt = |l: [f64; 3]| [l[0], l[0] * l[1] / 100.0, l[0] * l[2] / 100.0];
    let (g, b) = (hunt(g), hunt(b));
    let hyab = (g[0] - b[0]).abs() + ((g[1] - b[1]).powi(2) + (g[2] - b[2]).powi(2)).sqrt();
    assert!((colour::max_error() - hyab.powf(0.7)).abs() < 1e-3);
    // YCxCz and back is the identity
    let ycc = colour::linear_rgb_to_ycxcz([0.3, 0.6, 0.1]);
    let back = colour::xyz_to_linear_rgb(colour::ycxcz_to_xyz(ycc));
    assert!(close(back, [0.3, 0.6, 0.1], 1e-12));
    // the error remapping: 0 → 0, the knee → p_t, the largest error → 1
    let cmax = colour::max_error();
    assert_eq!(colour::colour_error(0.0, cmax), 0.0);
    let knee = (colour::PC * cmax).powf(1.0 / colour::QC);
    assert!((colour::colour_error(knee, cmax) - colour::PT).abs() < 1e-12);
    assert!((colour::colour_error(cmax.powf(1.0 / colour::QC), cmax) - 1.0).abs() < 1e-12);
}

#[test]
fn quartiles_of_a_known_map() {
    let stats = FlipStats::of(&[0.4, 0.1, 0.3, 0.2, 0.0]);
    let close = |a: f64, b: f64| (a - b).abs() < 1e-7;
    assert!(close(stats.mean, 0.2) && close(stats.min, 0.0) && close(stats.max, 0.4));
    assert!(close(stats.q1, 0.1) && close(stats.median, 0.2) && close(stats.q3, 0.3));
    // between order statistics: four values, Q1 at position 0.75
    let even = FlipStats::of(&[0.0, 1.0, 2.0, 3.0]);
    assert!(close(even.q1, 0.75) && close(even.median, 1.5) && close(even.q3, 2.25));
}
