//! FLIP's colour pipeline (Andersson et al. 2020, section 3.1): linear sRGB to the opponent
//! space YCxCz (where the contrast sensitivity filters apply, because it is linear in XYZ), and
//! after filtering to Hunt-adjusted CIELAB, where colour differences are measured with HyAB and
//! mapped to [0, 1].

use std::sync::OnceLock;

/// Exponent applied to the HyAB distance (the paper's q_c).
pub const QC: f64 = 0.7;
/// Fraction of the largest distance where the remapping changes slope (p_c).
pub const PC: f64 = 0.4;
/// Error the remapping assigns at that point (p_t).
pub const PT: f64 = 0.95;

type Mat3 = [[f64; 3]; 3];

/// Linear sRGB → XYZ and back, derived from the sRGB primaries and the D65 white point
/// (IEC 61966-2-1 chromaticities) rather than typed in, so the pair is exactly inverse.
fn matrices() -> &'static (Mat3, Mat3) {
    static M: OnceLock<(Mat3, Mat3)> = OnceLock::new();
    M.get_or_init(|| {
        let xy = [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]];
        let white_xy = [0.3127, 0.3290];
        let to_xyz = |p: [f64; 2]| [p[0] / p[1], 1.0, (1.0 - p[0] - p[1]) / p[1]];
        let primaries: Mat3 = {
            let cols = xy.map(to_xyz);
            [0, 1, 2].map(|r| [0, 1, 2].map(|c| cols[c][r]))
        };
        let white = to_xyz(white_xy);
        let inv_p = invert(&primaries);
        let scale = mul_vec(&inv_p, white);
        let rgb_to_xyz: Mat3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| primaries[r][c] * scale[c]));
        (rgb_to_xyz, invert(&rgb_to_xyz))
    })
}

fn mul_vec(m: &Mat3, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

fn invert(m: &Mat3) -> Mat3 {
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]
    };
    let det = m[0][0] * cof(0, 0) + m[0][1] * cof(0, 1) + m[0][2] * cof(0, 2);
    // the adjugate is the transposed cofactor matrix
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| cof(c, r) / det))
}

pub fn linear_rgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    mul_vec(&matrices().0, rgb)
}

pub fn xyz_to_linear_rgb(xyz: [f64; 3]) -> [f64; 3] {
    mul_vec(&matrices().1, xyz)
}

/// XYZ of the D65 white the sRGB primaries sum to (Y = 1).
pub fn white_xyz() -> [f64; 3] {
    linear_rgb_to_xyz([1.0, 1.0, 1.0])
}

/// YCxCz: CIELAB with the cube root left out, so that it stays linear in XYZ and filtering in
/// it is filtering of light.
pub fn xyz_to_ycxcz(xyz: [f64; 3]) -> [f64; 3] {
    let w = white_xyz();
    let [x, y, z] = [xyz[0] / w[0], xyz[1] / w[1], xyz[2] / w[2]];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

pub fn ycxcz_to_xyz(ycxcz: [f64; 3]) -> [f64; 3] {
    let w = white_xyz();
    let y = (ycxcz[0] + 16.0) / 116.0;
    let x = y + ycxcz[1] / 500.0;
    let z = y - ycxcz[2] / 200.0;
    [x * w[0], y * w[1], z * w[2]]
}

pub fn linear_rgb_to_ycxcz(rgb: [f64; 3]) -> [f64; 3] {
    xyz_to_ycxcz(linear_rgb_to_xyz(rgb))
}

/// CIELAB relative to the D65 white (CIE 15 with its linear segment below (6/29)³).
pub fn xyz_to_lab(xyz: [f64; 3]) -> [f64; 3] {
    let w = white_xyz();
    let delta: f64 = 6.0 / 29.0;
    let f = |t: f64| {
        if t > delta.powi(3) {
            t.cbrt()
        } else {
            t / (3.0 * delta * delta) + 4.0 / 29.0
        }
    };
    let [fx, fy, fz] = [f(xyz[0] / w[0]), f(xyz[1] / w[1]), f(xyz[2] / w[2])];
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// The Hunt effect (chroma looks weaker in the dark): a and b scaled by L / 100.
pub fn hunt(lab: [f64; 3]) -> [f64; 3] {
    [lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]]
}

/// Hunt-adjusted CIELAB of a linear sRGB colour clamped to the displayable [0, 1].
pub fn linear_rgb_to_hunt_lab(rgb: [f64; 3]) -> [f64; 3] {
    hunt(xyz_to_lab(linear_rgb_to_xyz(
        rgb.map(|c| c.clamp(0.0, 1.0)),
    )))
}

/// HyAB (Abasi et al. 2020): city-block in lightness, Euclidean in the chromatic plane, which
/// suits large colour differences better than ΔE*ab.
pub fn hyab(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).abs() + ((a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The largest colour error, raised to q_c: between pure green and pure blue, the pair of sRGB
/// colours furthest apart in Hunt-adjusted HyAB.
pub fn max_error() -> f64 {
    let green = linear_rgb_to_hunt_lab([0.0, 1.0, 0.0]);
    let blue = linear_rgb_to_hunt_lab([0.0, 0.0, 1.0]);
    hyab(green, blue).powf(QC)
}

/// Maps a HyAB distance to FLIP's colour error in [0, 1]: its q_c power, linear up to p_c of
/// the largest error where it reaches p_t, then linear up to 1 at the largest error, so that
/// most of the range separates small differences.
pub fn colour_error(hyab_distance: f64, cmax: f64) -> f64 {
    let e = hyab_distance.powf(QC);
    let knee = PC * cmax;
    if e < knee {
        e * PT / knee
    } else {
        PT + (e - knee) / (cmax - knee) * (1.0 - PT)
    }
}

/// sRGB transfer function, decoding an encoded value in [0, 1] to linear light.
pub fn srgb_to_linear(encoded: f64) -> f64 {
    if encoded <= 0.04045 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// The inverse of [`srgb_to_linear`] for a linear value in [0, 1].
pub fn linear_to_srgb(linear: f64) -> f64 {
    let c = linear.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}
