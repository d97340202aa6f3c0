//! Off-axis PSFs (the kernels' source) against geometric optics: a point well out of focus at
//! 30° in the wide-angle eye spreads over the physical pupil ellipse, so the PSF's second
//! moments along the tangential and sagittal axes equal the variance of the ray angles ∇W
//! over that ellipse, computed here by quadrature in physical pupil coordinates from the
//! measured wavefront plus the object's vergence (|q|²·ΔD/2). Negative control: the same
//! coefficients treated as a circular pupil (the on-axis pipeline) miss the ratio.

use ocular::eye::{measure_field, Eye};
use ocular::optics::zernike::basis_values;
use ocular::psf::{
    cropped_psf, field_column, frame_half_field_deg, FieldAxes, KernelSettings, Screen,
};

/// Variances (rad²) of the ray angle along x and y over the ellipse with semi-axes `a`
/// (mm), for the wavefront Σ c_j Z_j(x/a₀, y/a₁) + ΔD·|q|²/2 (µm, q in mm).
fn geometric_variance(c: &[f64], a: [f64; 2], delta_d: f64) -> [f64; 2] {
    let order = ocular::optics::zernike::order_for_len(c.len());
    let mut z = vec![0.0; c.len()];
    let mut w = |x: f64, y: f64| {
        basis_values(order, x / a[0], y / a[1], &mut z);
        z.iter().zip(c).map(|(z, c)| z * c).sum::<f64>() + 0.5 * delta_d * (x * x + y * y)
    };
    let (nr, na, h) = (40, 64, 1e-5);
    let (mut s, mut s2) = ([0.0; 2], [0.0; 2]);
    for i in 0..nr {
        let rho = ((i as f64 + 0.5) / nr as f64).sqrt();
        for j in 0..na {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / na as f64;
            let (x, y) = (a[0] * rho * phi.cos(), a[1] * rho * phi.sin());
            // µm per mm = 1e-3 rad
            let gx = 1e-3 * (w(x + h, y) - w(x - h, y)) / (2.0 * h);
            let gy = 1e-3 * (w(x, y + h) - w(x, y - h)) / (2.0 * h);
            for (k, g) in [gx, gy].into_iter().enumerate() {
                s[k] += g;
                s2[k] += g * g;
            }
        }
    }
    let n = (nr * na) as f64;
    [0, 1].map(|k| s2[k] / n - (s[k] / n).powi(2))
}

/// Variances (rad²) of a cropped PSF along screen x and retinal y.
fn psf_variance(values: &[f32], half: usize, pitch_rad: f64) -> [f64; 2] {
    let side = 2 * half + 1;
    let (mut m0, mut m1, mut m2) = (0.0, [0.0; 2], [0.0; 2]);
    for (row, line) in values.chunks(side).enumerate() {
        for (col, &v) in line.iter().enumerate() {
            let v = v as f64;
            let x = (col as f64 - half as f64) * pitch_rad;
            let y = (half as f64 - row as f64) * pitch_rad;
            m0 += v;
            for (k, p) in [x, y].into_iter().enumerate() {
                m1[k] += v * p;
                m2[k] += v * p * p;
            }
        }
    }
    [0, 1].map(|k| m2[k] / m0 - (m1[k] / m0).powi(2))
}

#[test]
fn defocused_point_at_30_degrees_spreads_over_the_pupil_ellipse() {
    let eye = Eye::navarro_wide();
    let settings = KernelSettings::default();
    let wl = [612.0, 549.0, 464.0];
    let field = [30.0, 0.0];
    let col = field_column(&eye, 4.0, 0.0, wl, &settings, field).unwrap();
    let ch = &col.channels[1];
    let screen = Screen {
        fov_y_deg: 20.0,
        height_px: 400,
    };
    let object_d = 4.0;
    let delta_d = ch.focus_vergence - ch.vergence_at_pupil(object_d);
    let sys = col.eye.system().unwrap();
    let m = measure_field(&sys, ch.wavelength_nm, 4.0, None, field, 6).unwrap();
    let want = geometric_variance(
        &m.measurement.coefficients_um,
        m.field.semi_axes_mm,
        delta_d,
    );
    let psf = cropped_psf(ch, object_d, &screen, &settings).unwrap();
    let pitch_rad = psf.pitch_lambda_na * ch.radians_per_lambda_na();
    let got = psf_variance(&psf.values, psf.half, pitch_rad);
    let (sg, sw) = (got.map(f64::sqrt), want.map(f64::sqrt));
    eprintln!(
        "σ tangential {:.3e} vs geometric {:.3e} rad, sagittal {:.3e} vs {:.3e} rad",
        sg[0], sw[0], sg[1], sw[1]
    );
    for k in 0..2 {
        assert!(
            (sg[k] / sw[k] - 1.0).abs() < 0.05,
            "axis {k}: σ {} vs geometric {}",
            sg[k],
            sw[k]
        );
    }
    let ratio = (sg[0] / sg[1]) / (sw[0] / sw[1]);
    assert!((ratio - 1.0).abs() < 0.03, "t/s ratio off by {ratio}");
    // Negative control: the same channel as if its pupil were the on-axis circle.
    let mut circle = ch.clone();
    circle.field = None;
    let psf = cropped_psf(&circle, object_d, &screen, &settings).unwrap();
    let pitch_rad = psf.pitch_lambda_na * ch.radians_per_lambda_na();
    let bad = psf_variance(&psf.values, psf.half, pitch_rad).map(f64::sqrt);
    let bad_ratio = (bad[0] / bad[1]) / (sw[0] / sw[1]);
    eprintln!("circle treatment: t/s ratio off by {bad_ratio:.3}");
    assert!((bad_ratio - 1.0).abs() > 0.1);
}

#[test]
fn field_axes_parse_and_frame_range() {
    let a = FieldAxes::parse("-40..40:5,-20..20:3").unwrap();
    assert_eq!(a.h_deg, vec![-40.0, -20.0, 0.0, 20.0, 40.0]);
    assert_eq!(a.v_deg, vec![-20.0, 0.0, 20.0]);
    assert_eq!(a.nodes().len(), 15);
    assert_eq!(
        FieldAxes::parse("10..10:1,0..0:1").unwrap().nodes(),
        vec![[10.0, 0.0]]
    );
    for bad in [
        "-70..0:3,0..0:1",
        "0..10:0,0..0:1",
        "10..0:3,0..0:1",
        "0..10:3",
        "55..55:1,55..55:1",
    ] {
        let e = FieldAxes::parse(bad).unwrap_err();
        assert!(e.contains("--field-deg"), "{e}");
    }
    // 16:9 at a 60° vertical field: ±45.8° horizontally.
    let [h, v] = frame_half_field_deg(60.0, 1280, 720);
    assert!((h - (30f64.to_radians().tan() * 16.0 / 9.0).atan().to_degrees()).abs() < 1e-12);
    assert!((h - 45.8).abs() < 0.1 && v == 30.0);
}

/// The plan covers only the frame and its steps pass the measured tolerance; a plan with a
/// node fewer per axis fails it (the count is the coarsest that passes).
#[test]
fn field_plan_covers_the_frame_with_the_coarsest_passing_steps() {
    use ocular::psf::{plan_field_axes, Probe, FIELD_TOLERANCE_UM};
    let sys = Eye::navarro_wide().system().unwrap();
    let probe = Probe {
        sys: &sys,
        wavelength_nm: 555.0,
        pupil_mm: 4.0,
        object_distance_m: None,
    };
    let plan = plan_field_axes(&probe, 60.0, 1280, 720, FIELD_TOLERANCE_UM).unwrap();
    let [h, v] = frame_half_field_deg(60.0, 1280, 720);
    let a = &plan.axes;
    assert!((a.h_deg[0] + h).abs() < 1e-9 && (a.h_deg.last().unwrap() - h).abs() < 1e-9);
    assert!((a.v_deg[0] + v).abs() < 1e-9 && (a.v_deg.last().unwrap() - v).abs() < 1e-9);
    eprintln!(
        "plan: {} × {} nodes, worst {:.4} µm",
        a.h_deg.len(),
        a.v_deg.len(),
        plan.worst_error_um
    );
    assert!(plan.worst_error_um <= FIELD_TOLERANCE_UM);
    // Independent check along h: linear interpolation at quarter points of each step.
    let coeffs = |f: [f64; 2]| {
        let m = measure_field(&sys, 555.0, 4.0, None, f, 6).unwrap();
        m.measurement.coefficients_um
    };
    let fewer = a.h_deg.len() - 1;
    let xs = ocular::psf::linspace(-h, h, fewer);
    let mut worst_fewer = 0.0f64;
    for k in 0..fewer - 1 {
        let (c0, c1) = (coeffs([xs[k], 0.0]), coeffs([xs[k + 1], 0.0]));
        let cm = coeffs([0.5 * (xs[k] + xs[k + 1]), 0.0]);
        let e: f64 = (3..c0.len())
            .map(|j| (0.5 * (c0[j] + c1[j]) - cm[j]).powi(2))
            .sum();
        worst_fewer = worst_fewer.max(e.sqrt());
    }
    assert!(
        worst_fewer > FIELD_TOLERANCE_UM,
        "one node fewer still passes: {worst_fewer}"
    );
    // A frame beyond the traced field is clamped, and says so.
    let wide = plan_field_axes(&probe, 100.0, 1920, 1080, 0.2).unwrap();
    assert!(!wide.notes.is_empty());
    let corner = [
        *wide.axes.h_deg.last().unwrap(),
        *wide.axes.v_deg.last().unwrap(),
    ];
    assert!(ocular::eye::eccentricity_deg(corner) <= 60.0);
}
