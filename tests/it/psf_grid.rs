//! The PSF grid precomputation: normalisation, cropping, resampling, orientation, the defocus
//! parameter against a direct measurement, focus behaviour of a healthy eye, planning and
//! extreme inputs. Small grids only: each test runs in seconds in release mode.

use ocular::eye::{accommodate, measure, trace_range, Eye, Ray};
use ocular::optics::defocus_f_from_c20;
use ocular::psf::{
    compute_grid, cropped_psf, cropped_psf_at_f, kernel_side, level_block_radius, level_count,
    no_progress, plan_for_scene, ChannelOptics, ColumnOptics, CroppedPsf, DioptreAxis, ExactEye,
    GridAxes, KernelSettings, SceneNeeds, Screen,
};
use ocular::render::reference::ExactKernels;

const WL: [f64; 3] = [612.0, 549.0, 464.0];

fn screen() -> Screen {
    Screen {
        fov_y_deg: 20.0,
        height_px: 240,
    }
}

fn small_axes() -> GridAxes {
    GridAxes {
        objects: DioptreAxis::spanning(0.0, 4.0, 9),
        focus_d: vec![1.0],
        pupils_mm: vec![4.0],
        wavelengths_nm: WL,
    }
}

/// Centroid (x right, y down) in pixels of a square kernel relative to its centre.
fn centroid(values: &[f64]) -> (f64, f64) {
    let side = (values.len() as f64).sqrt().round() as usize;
    let c = (side / 2) as f64;
    let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
    for (t, v) in values.iter().enumerate() {
        sx += v * ((t % side) as f64 - c);
        sy += v * ((t / side) as f64 - c);
        s += v;
    }
    (sx / s, sy / s)
}

/// A cropped PSF binned into the pixels of a kernel of `radius` with `samples_per_px` samples
/// per pixel by brute force: each sample a unit box, split between the pixels it overlaps
/// (screen orientation: grid rows run from +y at the top, the screen shows +y downwards).
/// With tens of samples per pixel this is the pixel-integrated PSF to a fraction of a
/// sample.
fn binned_kernel(p: &CroppedPsf, radius: u32, samples_per_px: f64) -> Vec<f64> {
    let n = p.side();
    let k = p.half as f64;
    let side = 2 * radius as usize + 1;
    let window = (radius as f64 + 0.5) * samples_per_px;
    // the pixels (index, overlap) a unit box centred at offset s covers
    let split = |s: f64| -> Vec<(usize, f64)> {
        let (a, b) = ((s - 0.5).max(-window), (s + 0.5).min(window));
        let mut out = Vec::new();
        if b <= a {
            return out;
        }
        let first = ((a + window) / samples_per_px).floor() as usize;
        let last = (((b + window) / samples_per_px).ceil() as usize).min(side);
        for i in first..last {
            let lo = i as f64 * samples_per_px - window;
            let ov = b.min(lo + samples_per_px) - a.max(lo);
            if ov > 0.0 {
                out.push((i, ov));
            }
        }
        out
    };
    let mut out = vec![0.0; side * side];
    for q in 0..n {
        let rows = split(k - q as f64);
        for i in 0..n {
            let v = f64::from(p.values[q * n + i]);
            if v == 0.0 {
                continue;
            }
            for (x, wx) in split(i as f64 - k) {
                for &(y, wy) in &rows {
                    out[y * side + x] += v * wx * wy;
                }
            }
        }
    }
    let total: f64 = out.iter().sum();
    out.iter_mut().for_each(|v| *v /= total);
    out
}

/// A channel with a given residual wavefront (OSA µm pairs) over `pupil_mm`.
fn channel(pairs: &[(usize, f64)], pupil_mm: f64, settings: &KernelSettings) -> ChannelOptics {
    let mut c = vec![0.0; 28];
    for &(j, v) in pairs {
        c[j] = v;
    }
    ChannelOptics::from_wavefront(&c, 549.0, pupil_mm, 1.0, 0.003, settings)
}

#[test]
fn kernels_sum_to_one_and_crops_keep_the_energy() {
    let settings = KernelSettings::default();
    let (grid, report) = compute_grid(
        &Eye::navarro(),
        &small_axes(),
        &screen(),
        &settings,
        &no_progress,
    )
    .unwrap();
    assert_eq!(report.psfs_computed, 27);
    assert!(report.min_kept_energy >= settings.energy, "{report:?}");
    let set = &grid.sets[0];
    assert!(grid.max_radius_px >= 3, "Rmax {}", grid.max_radius_px);
    for level in 0..level_count(grid.max_radius_px) {
        let r = level_block_radius(level);
        for o in 0..set.objects.count {
            let k = set.kernel(level, o);
            assert_eq!(k.len(), kernel_side(r) * kernel_side(r));
            for c in 0..3 {
                let s: f64 = k.iter().map(|t| f64::from(t[c])).sum();
                // the levels an object distance holds sum to one, the others are zero
                let expected = if level <= set.top_level[o] { 1.0 } else { 0.0 };
                assert!((s - expected).abs() < 1e-5, "r {r} o {o} c {c}: sum {s}");
                assert!(k.iter().all(|t| t[c] >= 0.0));
            }
        }
    }
    // every PSF of the grid, cropped at several fractions
    let col = ColumnOptics::new(&Eye::navarro(), 4.0, 1.0, WL, &settings).unwrap();
    for fraction in [0.9, 0.99, 0.999] {
        let s = KernelSettings {
            energy: fraction,
            ..settings.clone()
        };
        for d in [0.0, 1.0, 3.0] {
            let p = cropped_psf(&col.channels[1], d, &screen(), &s).unwrap();
            assert!(p.kept_energy >= fraction, "{d} D: {}", p.kept_energy);
            assert!(p.side() <= p.grid_side);
        }
    }
}

/// The kernels are the PSF integrated over whole pixels: against a brute-force binning of
/// the PSF's samples (no centroid correction on either side).
#[test]
fn resampling_integrates_over_pixels() {
    let settings = KernelSettings::default();
    // coma and trefoil: a PSF whose centroid is off its centre
    let ch = channel(&[(7, 0.25), (8, 0.2), (9, -0.15)], 5.0, &settings);
    for f in [0.0, 15.0, -40.0] {
        let p = cropped_psf_at_f(&ch, f, &screen(), &settings).unwrap();
        // natural size: the natural half-width (samples) spans natural + 0.5 px
        let natural = p.natural_radius_px();
        for radius in [natural.ceil() as u32, 2 * natural.ceil() as u32 + 1] {
            let support = if radius == natural.ceil() as u32 {
                natural + 0.5
            } else {
                radius as f64 + 0.5
            };
            let samples_per_px = p.natural_half_samples / support;
            let k = p.resample(radius, support);
            let binned = binned_kernel(&p, radius, samples_per_px);
            let (kx, ky) = centroid(&k);
            let (ex, ey) = centroid(&binned);
            let worst = k
                .iter()
                .zip(&binned)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                worst < 0.005,
                "f {f}, radius {radius}: a pixel differs by {worst}"
            );
            assert!(
                (kx - ex).abs() < 0.02 && (ky - ey).abs() < 0.02,
                "f {f}, radius {radius}: kernel centroid ({kx:.3}, {ky:.3}) vs binned ({ex:.3}, {ey:.3}) px"
            );
        }
    }
}

#[test]
fn nearer_and_farther_than_focus_differ_once_the_pupil_is_asymmetric() {
    let settings = KernelSettings::default();
    let diff = |ch: &ChannelOptics, f: f64| {
        let a = cropped_psf_at_f(ch, f, &screen(), &settings).unwrap();
        let b = cropped_psf_at_f(ch, -f, &screen(), &settings).unwrap();
        let r = 8;
        let ka = a.resample(r, r as f64 + 0.5);
        let kb = b.resample(r, r as f64 + 0.5);
        ka.iter().zip(&kb).map(|(x, y)| (x - y).abs()).sum::<f64>()
    };
    // spherical aberration and coma: before- and behind-focus PSFs differ
    let aberrated = channel(&[(12, 0.15), (7, 0.1)], 5.0, &settings);
    let d = diff(&aberrated, 20.0);
    assert!(d > 0.1, "aberrated eye: L1 difference {d}");
    // an aberration-free pupil is symmetric through focus: |U(f)| = |U(−f)|
    let perfect = channel(&[], 5.0, &settings);
    let d0 = diff(&perfect, 20.0);
    assert!(d0 < 1e-6, "perfect eye: L1 difference {d0}");
    // and a real eye: the objects 1 D nearer and 1 D farther than its green focus
    let col = ColumnOptics::new(&Eye::navarro(), 6.0, 2.0, WL, &settings).unwrap();
    let ex = ExactEye {
        column: col,
        screen: screen(),
        settings: settings.clone(),
        max_radius_px: 64,
    };
    let near = ex.kernel_checked(1, 3.0).unwrap().1;
    let far = ex.kernel_checked(1, 1.0).unwrap().1;
    let r = near.radius.max(far.radius) as i64;
    let l1: f32 = (-r..=r)
        .flat_map(|y| (-r..=r).map(move |x| (x, y)))
        .map(|(x, y)| (near.at(x, y) - far.at(x, y)).abs())
        .sum();
    assert!(l1 > 0.05, "Navarro 6 mm ±1 D: L1 difference {l1}");
}

#[test]
fn defocus_parameter_matches_a_direct_measurement() {
    let settings = KernelSettings::default();
    for eye in [Eye::navarro(), ocular::eye::keratoconus_like()] {
        let pupil = 5.0;
        // within reach of both (the keratoconus-like eye is about 3 D myopic)
        let focus_d = 5.0;
        let col = ColumnOptics::new(&eye, pupil, focus_d, WL, &settings).unwrap();
        assert!(!col.beyond_far_point);
        let sys = col.eye.system().unwrap();
        for (c, &wl) in WL.iter().enumerate() {
            let ch = &col.channels[c];
            for object_d in [0.1, 0.5, 3.0, 6.0, 9.5] {
                let direct = measure(&sys, wl, pupil, Some(1.0 / object_d), 6).unwrap();
                let f_direct = defocus_f_from_c20(direct.coefficient_um(2, 0), wl);
                let f = ch.defocus_f(object_d);
                // the neglected terms (r⁴/8L³ and the change of the eye's own aberrations with
                // vergence) stay within a fraction of a radian per dioptre
                let tol = 0.5 + 0.01 * f.abs();
                assert!(
                    (f - f_direct).abs() < tol,
                    "λ {wl}, object {object_d} D: f {f:.3} vs measured {f_direct:.3}"
                );
                // sign: farther than focus → positive (myopic-like) f relative to the focus
                let rel = f - ch.focus_f;
                assert_eq!(rel > 0.0, object_d < focus_d, "{object_d} D: {rel}");
            }
        }
    }
}

#[test]
fn the_eye_inverts_and_screen_kernels_show_the_object_space_psf() {
    // An object point above the axis (+y) images below it on the retina.
    let eye = Eye::navarro();
    let sys = eye.system().unwrap();
    let n = sys.indices(549.0);
    let ns = sys.surfaces.len();
    let mut ray = Ray::towards([0.0, 50.0, -1000.0], [0.0, 0.0, 3.6]);
    trace_range(&sys, &n, &mut ray, 0..ns).unwrap();
    let hit = ray.at(ray.to_plane(sys.retina_z_mm));
    assert!(hit[1] < -0.1, "retinal y {}", hit[1]);
    let mut ray = Ray::towards([50.0, 0.0, -1000.0], [0.0, 0.0, 3.6]);
    trace_range(&sys, &n, &mut ray, 0..ns).unwrap();
    assert!(ray.at(ray.to_plane(sys.retina_z_mm))[0] < -0.1);

    // Coma c(3,1) > 0: retinal core at +x, flare towards −x. Seen through the inversion with
    // +x to the subject's left, the screen kernel has its core right of centre and its flare
    // to the left; c(3,−1) > 0: core below centre, flare upwards.
    let settings = KernelSettings::default();
    let wide = Screen {
        fov_y_deg: 4.0,
        height_px: 400,
    };
    for (j, horizontal) in [(8usize, true), (7usize, false)] {
        let ch = channel(&[(j, 0.4)], 6.0, &settings);
        let p = cropped_psf_at_f(&ch, 0.0, &wide, &settings).unwrap();
        let natural = p.natural_radius_px();
        let r = natural.ceil() as u32;
        let k = p.resample(r, natural + 0.5);
        let side = 2 * r as usize + 1;
        let peak = k
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, _)| i)
            .unwrap();
        let (px, py) = (
            (peak % side) as f64 - r as f64,
            (peak / side) as f64 - r as f64,
        );
        let (cx, cy) = centroid(&k);
        if horizontal {
            assert!(
                px > 0.0 && cx < px - 0.5,
                "c(3,1): peak {px}, centroid {cx:.2}"
            );
            assert!(py.abs() < 1.0 && cy.abs() < 0.2);
        } else {
            assert!(
                py > 0.0 && cy < py - 0.5,
                "c(3,-1): peak {py}, centroid {cy:.2}"
            );
            assert!(px.abs() < 1.0 && cx.abs() < 0.2);
        }
    }
}

/// Least-squares line through (x, y); returns R².
fn r_squared(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    sxy * sxy / (sxx * syy)
}

#[test]
fn healthy_eye_blur_grows_linearly_and_channels_focus_apart() {
    let settings = KernelSettings::default();
    let focus_d = 2.0;
    let screen = Screen {
        fov_y_deg: 30.0,
        height_px: 720,
    };
    let col = ColumnOptics::new(&Eye::navarro(), 4.0, focus_d, WL, &settings).unwrap();
    let ex = ExactEye {
        column: col,
        screen,
        settings,
        max_radius_px: 512,
    };
    let objects: Vec<f64> = (0..=48).map(|i| 0.125 * i as f64).collect();
    let mut best = [0.0; 3];
    for (c, best_c) in best.iter_mut().enumerate() {
        let radii: Vec<f64> = objects
            .iter()
            .map(|&d| ex.kernel_checked(c, d).unwrap().0)
            .collect();
        let (i_min, _) = radii
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .unwrap();
        *best_c = objects[i_min];
        let best_d = *best_c;
        // outside the diffraction-limited zone (3 px around the minimum), on each side
        let floor = radii[i_min] + 3.0;
        for side in [-1.0, 1.0] {
            let pts: Vec<(f64, f64)> = objects
                .iter()
                .zip(&radii)
                .filter(|(d, r)| (**d - best_d) * side > 0.0 && **r > floor)
                .map(|(d, r)| ((d - best_d).abs(), *r))
                .collect();
            assert!(pts.len() >= 4, "channel {c} side {side}: {pts:?}");
            let r2 = r_squared(&pts);
            assert!(
                r2 > 0.99,
                "channel {c}, side {side}: R² {r2:.4} over {pts:?}"
            );
        }
    }
    // blue focuses in front of red: its sharpest object is nearer (more dioptres)
    assert!(
        best[0] < best[1] && best[1] < best[2],
        "best focus R/G/B {best:?}"
    );
    let shift = best[2] - best[0];
    assert!((0.6..=1.5).contains(&shift), "R–B focus shift {shift} D");
}

#[test]
fn a_single_frame_needs_one_column() {
    let reference = GridAxes::default();
    let frame = plan_for_scene(
        &SceneNeeds {
            dioptre_min: 0.0,
            dioptre_max: 10.125,
            focus_d: vec![0.5],
            pupils_mm: vec![4.2],
            screen: Screen::default(),
        },
        &reference,
    )
    .unwrap();
    assert_eq!(frame.axes.focus_d, vec![0.5]);
    assert_eq!(frame.axes.pupils_mm, vec![4.2]);
    // 0..10 D on the reference's 1/16 D steps, extended to the scene's 10.125 D
    assert_eq!(frame.axes.objects.count, 163);
    assert_eq!(frame.psfs, 489);
    assert_eq!(frame.skipped_psfs, 9660 - 489);
    // a shallow scene needs a few objects only, on the reference's sample positions
    let shallow = plan_for_scene(
        &SceneNeeds {
            dioptre_min: 1.3,
            dioptre_max: 2.0,
            focus_d: vec![1.0, 1.5, 2.0, 2.5],
            pupils_mm: vec![3.0, 3.5],
            screen: Screen::default(),
        },
        &reference,
    )
    .unwrap();
    let o = shallow.axes.objects;
    let step = reference.objects.step_d;
    assert!(o.min_d <= 1.3 - step + 1e-9 && o.max_d() >= 2.0 + step - 1e-9);
    assert_eq!(o.count, 15, "{o:?}"); // 1.25..2.0 brackets the scene, plus one each side
    assert!((o.min_d / step - (o.min_d / step).round()).abs() < 1e-9);
    // four focus values are covered by the reference points that bracket them
    assert!(
        shallow.axes.focus_d.len() <= 3,
        "{:?}",
        shallow.axes.focus_d
    );
    assert!(shallow.axes.focus_d[0] <= 1.0 && *shallow.axes.focus_d.last().unwrap() >= 2.5);
    assert_eq!(shallow.axes.pupils_mm, vec![3.0, 3.5]);
}

#[test]
fn extreme_settings_give_finite_kernels_or_clear_errors() {
    let settings = KernelSettings::default();
    let s = screen();
    let finite = |k: &ocular::render::reference::Kernel| {
        let sum: f32 = k.values.iter().sum();
        k.values.iter().all(|v| v.is_finite()) && (sum - 1.0).abs() < 1e-4
    };
    let cases: Vec<(&str, Eye, f64, f64, [f64; 3])> = vec![
        ("pupil 1 mm", Eye::navarro(), 1.0, 0.5, WL),
        ("pupil 8 mm", Eye::navarro(), 8.0, 0.5, WL),
        ("focus 0.1 m", Eye::navarro(), 4.0, 10.0, WL),
        (
            "-10 D eye",
            ocular::eye::hand_made_eye("myopia10-like").unwrap(),
            4.0,
            0.0,
            WL,
        ),
        (
            "400 / 700 nm",
            Eye::navarro(),
            4.0,
            1.0,
            [700.0, 549.0, 400.0],
        ),
    ];
    for (label, eye, pupil, focus, wl) in cases {
        match ColumnOptics::new(&eye, pupil, focus, wl, &settings) {
            Ok(col) => {
                let ex = ExactEye {
                    column: col,
                    screen: s,
                    settings: settings.clone(),
                    max_radius_px: 96,
                };
                for d in [0.0, 5.0, 20.0] {
                    for c in 0..3 {
                        let k = ex.kernel(c, d);
                        assert!(finite(&k), "{label}, {d} D, channel {c}");
                    }
                }
            }
            Err(e) => {
                let m = e.to_string();
                assert!(!m.is_empty() && !m.contains('\n'), "{label}: {m}");
                eprintln!("{label}: clear error: {m}");
            }
        }
    }
    // objects 0–20 D on a grid axis are accepted
    let axes = GridAxes {
        objects: DioptreAxis::spanning(0.0, 20.0, 5),
        focus_d: vec![0.0],
        pupils_mm: vec![3.0],
        wavelengths_nm: WL,
    };
    let (grid, _) = compute_grid(&Eye::navarro(), &axes, &s, &settings, &no_progress).unwrap();
    assert!(grid.validate().is_ok());
    // out-of-range axes are refused with the option's name
    let bad = GridAxes {
        pupils_mm: vec![0.1],
        ..axes
    };
    let e = compute_grid(&Eye::navarro(), &bad, &s, &settings, &no_progress).unwrap_err();
    assert!(e.to_string().contains("pupils-mm"), "{e}");
    assert_eq!(e.exit_code(), 2);
    // the accommodation used for these is measured, not assumed
    let acc = accommodate(&Eye::navarro(), Some(0.1), 4.0, 549.0).unwrap();
    assert!(acc.residual_d.abs() < 0.05);
}

/// The radius levels a set holds at each object distance (src/psf/level_band.rs) cover every
/// read a frame can make there, judged from the grid's own radii by the rule written here: a
/// fragment between two distances reads the levels of a radius interpolated between theirs;
/// a merged block at the defaults, the largest radius of pixels up to 0.25 D away (0.05 D per
/// merge level, five levels); the PSF texture, every set blended with its neighbours in pupil
/// and focus. Every held block is a whole kernel (sums to one, filled samples included), the
/// rest zero, and the band holds well under all the texels (the saving it is for: 60 % of them
/// on this small grid, whose largest kernel is a few pixels; 27 % of the healthy eye's full grid
/// at the paper's Rmax 48).
#[test]
fn the_levels_held_cover_every_read_and_nothing_more_is_stored() {
    let axes = GridAxes {
        objects: DioptreAxis::spanning(0.0, 6.0, 97),
        focus_d: vec![0.25, 2.0],
        pupils_mm: vec![3.0, 6.0],
        wavelengths_nm: WL,
    };
    let (grid, _) = compute_grid(
        &Eye::navarro(),
        &axes,
        &screen(),
        &KernelSettings::default(),
        &no_progress,
    )
    .unwrap();
    let no = grid.objects.count;
    let reach = (0.25 / grid.objects.step_d).ceil() as usize + 1;
    let (mut held, mut all) = (0usize, 0usize);
    for (s, set) in grid.sets.iter().enumerate() {
        let (p, f) = (s / 2, s % 2);
        for o in 0..no {
            let mut largest = 0.0f32;
            for (q, g) in [(p, f), (1 - p, f), (p, 1 - f), (1 - p, 1 - f)] {
                let other = grid.set(q, g);
                for near in o.saturating_sub(reach)..=(o + reach).min(no - 1) {
                    largest = other.radius_px[near]
                        .iter()
                        .copied()
                        .fold(largest, f32::max);
                }
            }
            let needed = ocular::psf::level_of_radius(f64::from(largest)).ceil() as u32;
            assert!(
                set.top_level[o] >= needed.min(level_count(grid.max_radius_px) - 1),
                "set {s}, object {o}: holds up to level {}, a read may ask for {needed}",
                set.top_level[o]
            );
        }
        for level in 0..level_count(grid.max_radius_px) {
            for o in 0..no {
                let k = set.kernel(level, o);
                all += k.len();
                let sums: Vec<f64> = (0..3)
                    .map(|c| k.iter().map(|t| f64::from(t[c])).sum())
                    .collect();
                if level <= set.top_level[o] {
                    held += k.len();
                    assert!(
                        sums.iter().all(|s| (s - 1.0).abs() < 1e-5),
                        "set {s}, object {o}, level {level}: held but sums {sums:?}"
                    );
                } else {
                    assert!(k.iter().all(|t| *t == [0.0; 3]), "set {s}, object {o}");
                }
            }
        }
    }
    assert!(
        (held as f64) < 0.65 * all as f64,
        "the band holds {held} of {all} texels"
    );
}
