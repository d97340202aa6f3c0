//! ENZ PSFs against an independent direct evaluation of the Fraunhofer integral, energy
//! conservation, orientation, and the symmetry properties the physics demands.

use num_complex::Complex64;
use ocular::aberrations::preset;
use ocular::optics::zernike::wavefront;
use ocular::optics::zernike::{num_terms, osa_index};
use ocular::optics::{
    bessel_j, bessel_j_sequence, compute_psf, defocus_f_from_dioptres, gauss_legendre_01, Psf,
    PsfRequest,
};
use std::f64::consts::PI;

/// Direct evaluation of U(x, y) = (1/π)∫∫ P e^{ifρ²} e^{i2π(xρcosθ + yρsinθ)} ρ dρ dθ with the
/// full pupil phase 2πW/λ (piston, tilt and defocus included, nothing moved into f or a shift).
/// Polar quadrature: Gauss–Legendre in ρ, the trapezoid rule (an FFT) in θ; the angular
/// integral against the kernel is done term by term with ∫e^{imθ}e^{iv cos(θ−φ)}dθ =
/// 2π i^m J_m(v) e^{imφ}.
struct Direct {
    nodes: Vec<(f64, f64)>,
    /// per radial node: harmonics P_m(ρ)e^{ifρ²} for m = −M/2..M/2 (index m + M/2)
    rings: Vec<Vec<Complex64>>,
    mmax: usize,
}

impl Direct {
    fn new(alpha: &[f64], wavelength_nm: f64, f: f64, nr: usize, ntheta: usize) -> Direct {
        let (xs, ws) = gauss_legendre_01(nr);
        let lam = wavelength_nm * 1e-3;
        let mmax = ntheta / 2 - 1;
        let mut rings = Vec::new();
        let fft = rustfft::FftPlanner::<f64>::new().plan_fft_forward(ntheta);
        for &rho in &xs {
            let mut ring: Vec<Complex64> = (0..ntheta)
                .map(|k| {
                    let th = 2.0 * PI * k as f64 / ntheta as f64;
                    let w = wavefront(alpha, rho * th.cos(), rho * th.sin());
                    Complex64::from_polar(1.0, 2.0 * PI * w / lam + f * rho * rho)
                })
                .collect();
            fft.process(&mut ring);
            let mut h = vec![Complex64::default(); 2 * mmax + 1];
            for m in -(mmax as i64)..=(mmax as i64) {
                let idx = m.rem_euclid(ntheta as i64) as usize;
                h[(m + mmax as i64) as usize] = ring[idx] / ntheta as f64;
            }
            rings.push(h);
        }
        Direct {
            nodes: xs.into_iter().zip(ws).collect(),
            rings,
            mmax,
        }
    }

    fn field(&self, x: f64, y: f64) -> Complex64 {
        let r = x.hypot(y);
        let phi = y.atan2(x);
        let mut jseq = vec![0.0; self.mmax + 1];
        let mut u = Complex64::default();
        let ipow = [
            Complex64::new(1.0, 0.0),
            Complex64::new(0.0, 1.0),
            Complex64::new(-1.0, 0.0),
            Complex64::new(0.0, -1.0),
        ];
        for ((rho, w), h) in self.nodes.iter().zip(&self.rings) {
            bessel_j_sequence(self.mmax, 2.0 * PI * r * rho, &mut jseq);
            let mut s = Complex64::default();
            for m in -(self.mmax as i64)..=(self.mmax as i64) {
                let am = m.unsigned_abs() as usize;
                let jm = if m < 0 && am % 2 == 1 {
                    -jseq[am]
                } else {
                    jseq[am]
                };
                if jm == 0.0 {
                    continue;
                }
                let e = Complex64::from_polar(1.0, m as f64 * phi);
                s += h[(m + self.mmax as i64) as usize] * ipow[m.rem_euclid(4) as usize] * e * jm;
            }
            u += s * (w * rho);
        }
        // (1/π)·2π = 2
        u * 2.0
    }
}

fn alpha_vec(coeffs: &[(u32, i32, f64)]) -> Vec<f64> {
    let order = coeffs.iter().map(|c| c.0).max().unwrap_or(0).max(2);
    let mut a = vec![0.0; num_terms(order)];
    for &(n, m, v) in coeffs {
        a[osa_index(n, m)] += v;
    }
    a
}

/// Compare an ENZ PSF with the direct integral on the central row, column, diagonal and a
/// scatter of pixels; returns the largest error relative to the peak.
fn compare_with_direct(req: &PsfRequest, nr: usize, ntheta: usize) -> (f64, Psf) {
    let psf = compute_psf(req).expect("valid request");
    let alpha = alpha_vec(&req.coefficients_um);
    let d = Direct::new(&alpha, req.wavelength_nm, req.defocus_f, nr, ntheta);
    let n = req.size;
    let half = (n / 2) as f64;
    let mut pix: Vec<(usize, usize)> = Vec::new();
    for i in 0..n {
        pix.push((i, n / 2));
        pix.push((n / 2, i));
        pix.push((i, i));
    }
    let mut seed = 12345u64;
    for _ in 0..120 {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let a = (seed >> 33) as usize % n;
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let b = (seed >> 33) as usize % n;
        pix.push((a, b));
    }
    let mut worst: f64 = 0.0;
    for &(row, col) in &pix {
        let x = (col as f64 - half) * req.pitch_lambda_over_na;
        let y = (half - row as f64) * req.pitch_lambda_over_na;
        let iref = d.field(x, y).norm_sqr();
        let ienz = psf.intensity[row * n + col];
        worst = worst.max((iref - ienz).abs());
    }
    eprintln!(
        "direct vs ENZ: max |dI|/peak = {:.2e} (degree {}, f {:.1}, {} px)",
        worst / psf.peak_intensity,
        psf.beta_degree,
        psf.defocus_f,
        pix.len()
    );
    (worst / psf.peak_intensity, psf)
}

fn request(coeffs: Vec<(u32, i32, f64)>, pupil: f64, wl: f64, f: f64, pitch: f64) -> PsfRequest {
    let mut r = PsfRequest::new(coeffs, pupil, wl, pitch, 48);
    r.defocus_f = f;
    r
}

#[test]
fn direct_unaberrated() {
    let req = request(vec![], 5.0, 550.0, 0.0, 0.15);
    let (err, psf) = compare_with_direct(&req, 80, 16);
    assert!(
        (psf.peak_intensity - 1.0).abs() < 1e-9,
        "peak {}",
        psf.peak_intensity
    );
    assert!(err < 1e-6, "rel err {err:e}");
}

#[test]
fn direct_coma() {
    let req = request(vec![(3, 1, 0.3), (3, -1, 0.1)], 5.0, 550.0, 0.0, 0.15);
    let (err, psf) = compare_with_direct(&req, 120, 64);
    assert!(err < 0.01, "rel err {err:e}, degree {}", psf.beta_degree);
    assert!(err < 1e-4, "ENZ should be far better than 1%: {err:e}");
}

#[test]
fn direct_astigmatism_2um() {
    // |c| = 2 µm of astigmatism at 550 nm: ±56 rad of phase, the expansion degree must adapt.
    let req = request(vec![(2, -2, 1.2), (2, 2, 1.6)], 5.0, 550.0, 0.0, 0.5);
    let (err, psf) = compare_with_direct(&req, 400, 512);
    assert!(psf.beta_degree > 60, "degree {}", psf.beta_degree);
    assert!(err < 0.01, "rel err {err:e}, degree {}", psf.beta_degree);
}

#[test]
fn direct_defocus_1d_and_10d_at_6mm() {
    for (dd, pitch, nr) in [(1.0, 0.5, 400), (10.0, 4.0, 1800)] {
        let f = defocus_f_from_dioptres(dd, 6.0, 550.0);
        let req = request(vec![(4, 0, 0.1)], 6.0, 550.0, f, pitch);
        let (err, psf) = compare_with_direct(&req, nr, 32);
        assert!(err < 0.01, "{dd} D (f = {f}): rel err {err:e}");
        assert!(psf.defocus_f == f);
    }
}

#[test]
fn direct_keratoconus_preset() {
    let set = preset("keratoconus").unwrap();
    // Tilt (≈8 λ/NA) and c(2,0) (f ≈ 130) stay in the wavefront: the ENZ side moves them into
    // a shift and f, the direct side integrates them as phase.
    let mut req = PsfRequest::new(
        set.coefficients.clone(),
        set.pupil_diameter_mm,
        set.wavelength_nm,
        1.0,
        64,
    );
    req.beta_tolerance = 1e-6;
    let (err, psf) = compare_with_direct(&req, 500, 1024);
    assert!(err < 0.01, "rel err {err:e}, degree {}", psf.beta_degree);
    assert!(psf.defocus_f > 100.0);
}

fn circle_energy(psf: &Psf, radius: f64) -> f64 {
    let n = psf.size;
    let half = (n / 2) as f64;
    let p = psf.pitch_lambda_over_na;
    let mut s = 0.0;
    for row in 0..n {
        for col in 0..n {
            let x = (col as f64 - half) * p;
            let y = (half - row as f64) * p;
            if x.hypot(y) < radius {
                s += psf.intensity[row * n + col];
            }
        }
    }
    s * p * p * PI
}

#[test]
fn parseval_energy() {
    // Unaberrated: the encircled energy has the closed form 1 − J0²(2πR) − J1²(2πR).
    let radius = 40.0;
    let v = 2.0 * PI * radius;
    let ee = 1.0 - bessel_j(0, v).powi(2) - bessel_j(1, v).powi(2);
    let mut req = request(vec![], 5.0, 550.0, 0.0, 0.2);
    req.size = 440;
    let psf0 = compute_psf(&req).unwrap();
    let e0 = circle_energy(&psf0, radius);
    assert!((e0 - ee).abs() < 1e-3, "unaberrated {e0} vs {ee}");
    // Aberrated pupils spread light inside the circle but lose the same far diffraction tail.
    for coeffs in [
        vec![(3, 1, 0.3)],
        vec![(2, 2, 0.8), (4, 0, 0.2)],
        vec![(2, 0, 0.6), (3, -3, 0.2)],
    ] {
        req.coefficients_um = coeffs.clone();
        let psf = compute_psf(&req).unwrap();
        let e = circle_energy(&psf, radius);
        assert!((e - ee).abs() < 1e-3, "{coeffs:?}: {e} vs {ee}");
    }
}

fn peak_position(psf: &Psf) -> (f64, f64) {
    let n = psf.size;
    let half = (n / 2) as f64;
    let (mut best, mut at) = (-1.0, (0, 0));
    for row in 0..n {
        for col in 0..n {
            if psf.intensity[row * n + col] > best {
                best = psf.intensity[row * n + col];
                at = (row, col);
            }
        }
    }
    let p = psf.pitch_lambda_over_na;
    ((at.1 as f64 - half) * p, (half - at.0 as f64) * p)
}

fn centroid(psf: &Psf) -> (f64, f64) {
    let n = psf.size;
    let half = (n / 2) as f64;
    let p = psf.pitch_lambda_over_na;
    let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
    for row in 0..n {
        for col in 0..n {
            let i = psf.intensity[row * n + col];
            sx += i * (col as f64 - half) * p;
            sy += i * (half - row as f64) * p;
            s += i;
        }
    }
    (sx / s, sy / s)
}

#[test]
fn orientation_tilt_and_coma() {
    // positive x-tilt moves the spot to −x by 2c/λ (λ/NA units)
    let req = request(vec![(1, 1, 0.55)], 5.0, 550.0, 0.0, 0.25);
    let psf = compute_psf(&req).unwrap();
    let (px, py) = peak_position(&psf);
    assert!(
        (px + 2.0).abs() < 0.13 && py.abs() < 0.13,
        "peak at {px},{py}"
    );
    // positive y-tilt moves it to −y
    let req = request(vec![(1, -1, 0.55)], 5.0, 550.0, 0.0, 0.25);
    let (px, py) = peak_position(&compute_psf(&req).unwrap());
    assert!(
        (py + 2.0).abs() < 0.13 && px.abs() < 0.13,
        "peak at {px},{py}"
    );
    // positive c(3,1) coma: the sharp core (paraxial rays, −∂W/∂x > 0 near the centre) sits
    // at +x and the flare of the marginal rays (−∂W/∂x < 0 on average at the rim) spreads
    // towards −x, so the light's centroid lies on the −x side of the peak.
    let mut req = request(vec![(3, 1, 0.25)], 5.0, 550.0, 0.0, 0.2);
    req.size = 49; // odd: the grid is symmetric about the axis
    let psf = compute_psf(&req).unwrap();
    let (px, py) = peak_position(&psf);
    let (cx, cy) = centroid(&psf);
    assert!(px > 0.1 && py.abs() < 1e-9, "peak {px},{py}");
    assert!(
        cx < px - 0.1 && cy.abs() < 1e-6,
        "centroid {cx},{cy} peak {px}"
    );
    // c(3,−1) is the same along y: core at +y (rows run downwards, +y is up), tail towards −y
    let mut req = request(vec![(3, -1, 0.25)], 5.0, 550.0, 0.0, 0.2);
    req.size = 49;
    let psf = compute_psf(&req).unwrap();
    let (px, py) = peak_position(&psf);
    let (cx, cy) = centroid(&psf);
    assert!(py > 0.1 && px.abs() < 1e-9, "peak {px},{py}");
    assert!(cy < py - 0.1 && cx.abs() < 1e-6, "centroid {cx},{cy}");
}

#[test]
fn coma_mirrors_when_sign_flips() {
    let a = compute_psf(&request(
        vec![(3, 1, 0.3), (4, 0, 0.1)],
        5.0,
        550.0,
        7.0,
        0.2,
    ))
    .unwrap();
    let b = compute_psf(&request(
        vec![(3, 1, -0.3), (4, 0, 0.1)],
        5.0,
        550.0,
        7.0,
        0.2,
    ))
    .unwrap();
    let n = a.size;
    // mirror x → −x: col ↔ n − col (axis at n/2); compare the overlapping columns
    let mut worst: f64 = 0.0;
    for row in 0..n {
        for col in 1..n {
            let m = n - col;
            worst = worst.max((a.intensity[row * n + col] - b.intensity[row * n + m]).abs());
        }
    }
    assert!(worst < 1e-9 * a.peak_intensity, "mirror mismatch {worst:e}");
    // and it really is asymmetric
    let asym = (0..n)
        .map(|c| (a.intensity[(n / 2) * n + c] - a.intensity[(n / 2) * n + (n - c) % n]).abs())
        .fold(0.0, f64::max);
    assert!(asym > 1e-3 * a.peak_intensity);
}

#[test]
fn astigmatism_rotates_with_axis() {
    // c(2,2) and c(2,−2) with the same magnitude are the same astigmatism rotated by 45°;
    // rotating the sample grid by 90° swaps the sign of c(2,2).
    let psf_for = |c22: f64| {
        let mut r = request(vec![(2, 2, c22), (4, 0, 0.05)], 5.0, 550.0, 3.0, 0.25);
        r.size = 41;
        compute_psf(&r).unwrap()
    };
    let a = psf_for(0.4);
    let b = psf_for(-0.4);
    let n = a.size;
    let mut worst: f64 = 0.0;
    for row in 0..n {
        for col in 0..n {
            // 90° rotation about the centre (n odd so the axis is the centre pixel)
            let (r2, c2) = (col, n - 1 - row);
            worst = worst.max((a.intensity[row * n + col] - b.intensity[r2 * n + c2]).abs());
        }
    }
    assert!(
        worst < 1e-8 * a.peak_intensity,
        "90° rotation mismatch {worst:e}"
    );
    // 45°: c(2,−2) = c(2,2) rotated by 45°, so PSF_c(r, 45°) = PSF_a(r, 0°). Sampling `c` with
    // pitch p/√2 puts its diagonal pixel k at distance k·p, like pixel k on +x of `a`.
    let mut r = request(
        vec![(2, -2, 0.4), (4, 0, 0.05)],
        5.0,
        550.0,
        3.0,
        0.25 / 2f64.sqrt(),
    );
    r.size = 41;
    let c = compute_psf(&r).unwrap();
    let mid = n / 2;
    for k in 0..=mid {
        let ia = a.intensity[mid * n + mid + k];
        let ic = c.intensity[(mid - k) * n + mid + k];
        assert!(
            (ia - ic).abs() < 1e-7 * a.peak_intensity,
            "45° mismatch at pixel {k}: {ia} vs {ic}"
        );
    }
}

#[test]
fn behind_and_in_front_of_focus_differ_with_spherical_aberration() {
    let mk = |f: f64, c40: f64| {
        let mut r = request(vec![(4, 0, c40)], 5.0, 550.0, f, 0.3);
        r.size = 64;
        compute_psf(&r).unwrap()
    };
    // the largest pixel difference between the PSFs at +f and -f
    let asymmetry = |c40: f64| {
        let (front, back) = (mk(12.0, c40), mk(-12.0, c40));
        let diff = front
            .intensity
            .iter()
            .zip(&back.intensity)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        (diff, front.peak_intensity)
    };
    let (diff, peak) = asymmetry(0.25);
    assert!(
        diff > 0.05 * peak,
        "SA: ±f should differ, max diff {diff:e}"
    );
    // without spherical aberration (a symmetric pupil) the two are identical
    let (diff0, _) = asymmetry(0.0);
    assert!(diff0 < 1e-10, "no SA: ±f identical, diff {diff0:e}");
}

#[test]
fn radial_interpolation_holds_1e_6() {
    // A tilt forces the tabulated path (no symmetric grid); compare every pixel with the exact
    // point evaluation of the same field. Intensity error ≈ 2|U|·field error ≤ ~2e-6 of peak.
    use ocular::optics::{beta_from_alpha, split_wavefront, RadialAmplitude};
    for (f, pitch) in [(0.0, 0.3), (60.0, 0.9), (-300.0, 3.7)] {
        let coeffs = vec![(1, 1, 0.3), (3, -1, 0.15), (4, 0, 0.1), (3, 3, 0.05)];
        let mut req = request(coeffs.clone(), 5.0, 550.0, f, pitch);
        req.size = 40;
        let psf = compute_psf(&req).unwrap();
        assert!(psf.radial_taps > 0, "table path expected");
        let split = split_wavefront(&coeffs, 550.0, f, true);
        let be = beta_from_alpha(&split.alpha_um, 550.0, 5.0, None, req.beta_tolerance, 160);
        let rf = RadialAmplitude::new(&be.beta, be.degree, split.f);
        let n = req.size;
        let half = (n / 2) as f64;
        let mut worst: f64 = 0.0;
        let mut umax: f64 = 0.0;
        for row in 0..n {
            for col in 0..n {
                let x = (col as f64 - half) * pitch + split.tilt_shift.0;
                let y = (half - row as f64) * pitch + split.tilt_shift.1;
                let u = rf.at(x, y);
                umax = umax.max(u.norm());
                worst = worst.max((u.norm_sqr() - psf.intensity[row * n + col]).abs());
            }
        }
        eprintln!(
            "f={f}: taps {} step {:.3}: max |dI| = {worst:.2e}, peak {:.3e}",
            psf.radial_taps, psf.radial_step, psf.peak_intensity
        );
        assert!(
            worst < 2.5e-6 * umax * umax,
            "f={f}: {worst:e} vs field max {umax}"
        );
    }
}

#[test]
fn centred_grids_match_pointwise_field() {
    // Without tilt the grid is filled four mirror images at a time (exact radii or table);
    // every pixel must still equal the field evaluated at that point, for even and odd sizes.
    use ocular::optics::{beta_from_alpha, split_wavefront, RadialAmplitude};
    let coeffs = vec![
        (2, -2, 0.2),
        (3, 1, 0.15),
        (3, -3, 0.1),
        (4, 0, 0.1),
        (5, -1, 0.05),
    ];
    for (size, f, pitch) in [(32usize, 0.0, 0.3), (33, 40.0, 0.8), (20, -500.0, 9.0)] {
        let mut req = request(coeffs.clone(), 5.0, 550.0, f, pitch);
        req.size = size;
        let psf = compute_psf(&req).unwrap();
        let split = split_wavefront(&coeffs, 550.0, f, true);
        let be = beta_from_alpha(&split.alpha_um, 550.0, 5.0, None, req.beta_tolerance, 160);
        let rf = RadialAmplitude::new(&be.beta, be.degree, split.f);
        let half = (size / 2) as f64;
        let mut worst: f64 = 0.0;
        for row in 0..size {
            for col in 0..size {
                let x = (col as f64 - half) * pitch;
                let y = (half - row as f64) * pitch;
                let i = rf.at(x, y).norm_sqr();
                worst = worst.max((i - psf.intensity[row * size + col]).abs());
            }
        }
        assert!(
            worst < 3e-6 * psf.peak_intensity,
            "size {size} f {f} (taps {}): {worst:e}",
            psf.radial_taps
        );
    }
}

#[test]
fn through_focus_reuses_one_pupil_expansion() {
    use ocular::optics::{expand_pupil, psf_from_pupil};
    let set = preset("myopia").unwrap();
    let mut req = PsfRequest::new(
        vec![(2, 0, 5.4127), (4, 0, 0.04), (3, -1, 0.04)],
        set.pupil_diameter_mm,
        set.wavelength_nm,
        2.0,
        32,
    );
    let pupil = expand_pupil(&req).unwrap();
    assert!(
        (pupil.base_f - 200.5).abs() < 0.1,
        "c(2,0) → f: {}",
        pupil.base_f
    );
    for extra in [-200.5, -150.0, 0.0, 37.0] {
        req.defocus_f = extra;
        let a = psf_from_pupil(&pupil, &req).unwrap();
        let b = compute_psf(&req).unwrap();
        assert_eq!(a.intensity, b.intensity);
        assert_eq!(a.defocus_f, pupil.base_f + extra);
    }
    // refocused by the exact opposite f only the 0.057 µm RMS of higher orders is left:
    // Maréchal's exp(−(2π·RMS/λ)²) ≈ 0.64 (a slight underestimate at this level)
    req.defocus_f = -pupil.base_f;
    req.pitch_lambda_over_na = 0.25;
    let sharp = psf_from_pupil(&pupil, &req).unwrap();
    let rms = (2.0f64 * 0.04 * 0.04).sqrt();
    let marechal = (-(2.0 * PI * rms / (set.wavelength_nm * 1e-3)).powi(2)).exp();
    assert!(
        sharp.strehl > marechal && sharp.strehl < marechal + 0.1,
        "Strehl {} vs Maréchal {marechal}",
        sharp.strehl
    );
}
