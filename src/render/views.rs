//! Multi-view accumulation: the geometric-optics ground truth for scene inputs.
//!
//! The eye's entrance pupil is sampled at N points p (a Vogel spiral: equal-area, so every
//! view weighs 1/N of the pupil). From each p the scene is rasterised with a sheared frustum
//! that keeps the focus plane where it is (the accumulation-buffer method of Haeberli and
//! Akeley 1990): a point off that plane is seen displaced by its true parallax
//! p_⊥·(V_focus − 1/L), L its distance along the ray, so defocus blur comes from geometry and
//! sees around edges (hidden surfaces are rasterised). Each colour channel of the view is
//! then displaced by the focused eye's transverse ray aberration at p, the wavefront slope
//! −∇W_λ(p)/R (object-space radians; W the eye measured at that channel's wavelength with the
//! object at the focus distance, without piston and tilt, its residual defocus kept: the
//! chromatic focal shift and any error beyond the far point), and the views are averaged.
//!
//! What it shares with splat and the reference: the rasterised scene, the focused eye and its
//! measured Zernike coefficients per wavelength. It shares no kernel, no PSF and no blend. It
//! leaves out diffraction: compare against it where geometric blur dominates.
//!
//! Geometry, in the camera's frame (x right, y down, z forward): a pupil point at OSA (x, y)
//! (+x to the subject's left, +y up) lies at p = (−x·R, −y·R) metres, and a wavefront slope
//! g = ∇W (µm per pupil radius) turns the ray by (−g_x, −g_y)/R_µm radians on the screen, the
//! orientation of the kernels (see psf::project). The rasterised frustum carries the parallax
//! against a focus *plane* and the green channel's slope at the centre's scale; the rest is a
//! small per-pixel displacement applied by bilinear resampling: each channel's slope laid out
//! by the pinhole's local Jacobian (f/cos²θ radially, f/cosθ tangentially), and
//! p_⊥·V_focus·(1 − cosθ), which moves the sharp surface from the plane to the sphere of
//! points at the focus distance along their rays (the vergence convention of every method).
//! The pupil lies at the camera (the corneal vertex): vergences here are 1/d where the kernels
//! use 1/(d + e), e ≈ 3 mm the entrance pupil's depth (blur 1.5 % smaller at 0.2 m).

use glam::{DMat4, DVec3, DVec4};
use rayon::prelude::*;

use crate::gpu::Context;
use crate::optics::zernike::wavefront_gradient;
use crate::psf::defocus::ColumnOptics;
use crate::render::Rasterizer;
use crate::scene::FrameState;
use crate::{Error, Result};

/// Views per frame unless told otherwise (see docs/validation.md for the measured convergence).
pub const DEFAULT_VIEWS: u32 = 256;
/// Fewest and most views `--views` accepts.
pub const MIN_VIEWS: u32 = 2;
pub const MAX_VIEWS: u32 = 65536;

const GOLDEN_ANGLE: f64 = 2.399_963_229_728_653;

/// Pupil points on the unit disc (OSA axes), equal-area: point k at radius √((k + ½)/N) and
/// angle k·(golden angle). Every point stands for 1/N of the pupil's area.
pub fn pupil_points(count: u32) -> Vec<[f64; 2]> {
    let n = f64::from(count);
    (0..count)
        .map(|k| {
            let k = f64::from(k);
            let rho = ((k + 0.5) / n).sqrt();
            let th = k * GOLDEN_ANGLE;
            [rho * th.cos(), rho * th.sin()]
        })
        .collect()
}

/// The accumulated image and its own convergence.
pub struct ViewsImage {
    /// All N views averaged (linear RGB, alpha 1).
    pub color: Vec<[f32; 4]>,
    /// The even-numbered N/2 views averaged: `color` is this image with its views doubled.
    pub half_color: Vec<[f32; 4]>,
    pub views: u32,
    /// Wall-clock seconds: rasterising and read-back, and accumulation on the CPU.
    pub seconds_raster: f64,
    pub seconds_accumulate: f64,
}

/// Per-pixel maps from a small angular displacement to a screen displacement (pixels).
struct LocalMaps {
    /// Screen-aligned angle (right, down; radians) → pixels, laid out at the local scale.
    slope: Vec<[f32; 4]>,
    /// Pupil offset (right, down; metres) → the focus plane-to-sphere correction in pixels.
    sphere: Vec<[f32; 4]>,
}

fn local_maps(width: u32, height: u32, focal_px: f64, focus_d: f64) -> LocalMaps {
    let n = width as usize * height as usize;
    let mut slope = vec![[0.0f32; 4]; n];
    let mut sphere = vec![[0.0f32; 4]; n];
    for v in 0..height as usize {
        for u in 0..width as usize {
            let x = (u as f64 + 0.5 - 0.5 * f64::from(width)) / focal_px;
            let y = (v as f64 + 0.5 - 0.5 * f64::from(height)) / focal_px;
            let norm = (1.0 + x * x + y * y).sqrt();
            let d = DVec3::new(x, y, 1.0) / norm;
            let cos = 1.0 / norm;
            // Exact Jacobian of u = f·dx/dz, v = f·dy/dz for a tangent vector t at d.
            let jac = |t: DVec3| {
                [
                    focal_px * (t.x * d.z - d.x * t.z) / (d.z * d.z),
                    focal_px * (t.y * d.z - d.y * t.z) / (d.z * d.z),
                ]
            };
            let rho = (x * x + y * y).sqrt();
            let (cx, cy) = if rho < 1e-12 {
                (DVec3::X, DVec3::Y)
            } else {
                let (ex, ey) = (x / rho, y / rho);
                let sin = rho / norm;
                let radial = DVec3::new(cos * ex, cos * ey, -sin);
                let tangential = DVec3::new(-ey, ex, 0.0);
                // screen right = ex·radial − ey·tangential, down = ey·radial + ex·tangential
                (ex * radial - ey * tangential, ey * radial + ex * tangential)
            };
            let (a, b) = (jac(cx), jac(cy));
            let i = v * width as usize + u;
            slope[i] = [a[0] as f32, a[1] as f32, b[0] as f32, b[1] as f32];
            let k = focus_d * (1.0 - cos);
            let perp = |p: DVec3| (p - p.dot(d) * d) * k;
            let (a, b) = (jac(perp(DVec3::X)), jac(perp(DVec3::Y)));
            sphere[i] = [a[0] as f32, a[1] as f32, b[0] as f32, b[1] as f32];
        }
    }
    LocalMaps { slope, sphere }
}

/// Renders the scene state through the focused eye `column` (its pupil and focus) by
/// accumulating `views` rasterised views. `focus_d` is the focus vergence (1/m from the
/// camera, 0 = infinity) whose plane the frusta keep fixed.
pub fn render(
    ctx: &Context,
    rasterizer: &mut Rasterizer,
    state: &FrameState<'_>,
    (width, height): (u32, u32),
    column: &ColumnOptics,
    focus_d: f64,
    views: u32,
) -> Result<ViewsImage> {
    if !(MIN_VIEWS..=MAX_VIEWS).contains(&views) {
        return Err(Error::input(format!(
            "--views {views} is outside {MIN_VIEWS} to {MAX_VIEWS}"
        )));
    }
    let camera = &state.camera;
    let focal_px = camera.focal_length_px(height);
    let radius_m = 0.5e-3 * column.pupil_mm;
    let radius_um = 0.5e3 * column.pupil_mm;
    let maps = local_maps(width, height, focal_px, focus_d);
    let wavefronts: Vec<Vec<f64>> = column
        .channels
        .iter()
        .map(|ch| {
            let mut w = ch.alpha_um.clone();
            w[4] = ch.residual_c20_um;
            w
        })
        .collect();
    let forward = DVec3::from(camera.forward());
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    let projection = camera.projection_matrix(f64::from(width) / f64::from(height));
    let pixels = width as usize * height as usize;
    let mut sums = [vec![[0.0f32; 3]; pixels], vec![[0.0f32; 3]; pixels]];
    let (mut seconds_raster, mut seconds_accumulate) = (0.0, 0.0);
    for (k, [ox, oy]) in pupil_points(views).into_iter().enumerate() {
        let p = [-ox * radius_m, -oy * radius_m];
        // each channel's ray turn on the screen (right, down), radians
        let slopes: Vec<[f64; 2]> = wavefronts
            .iter()
            .map(|w| {
                let (gx, gy) = wavefront_gradient(w, ox, oy);
                [-gx / radius_um, -gy / radius_um]
            })
            .collect();
        // the frustum's own shift (px): parallax zero on the focus plane, green's slope
        let shift = [
            focal_px * (p[0] * focus_d + slopes[1][0]),
            focal_px * (p[1] * focus_d + slopes[1][1]),
        ];
        let position = DVec3::from(camera.position_m) + p[0] * right - p[1] * up;
        let view = DMat4::look_to_rh(position, forward, DVec3::Y);
        // x' = x + tx·w: a constant shift in pixels after the perspective division
        let shear = DMat4::from_cols(
            DVec4::X,
            DVec4::Y,
            DVec4::Z,
            DVec4::new(
                2.0 * shift[0] / f64::from(width),
                2.0 * shift[1] / f64::from(height),
                0.0,
                1.0,
            ),
        );
        let started = std::time::Instant::now();
        let frame = rasterizer.render_from(
            ctx,
            state,
            width,
            height,
            shear * projection * view,
            position.to_array(),
        )?;
        seconds_raster += started.elapsed().as_secs_f64();
        let started = std::time::Instant::now();
        accumulate(
            &mut sums[k % 2],
            &frame.color,
            (width as usize, height as usize),
            &maps,
            &slopes,
            p,
            [focal_px * slopes[1][0], focal_px * slopes[1][1]],
        );
        seconds_accumulate += started.elapsed().as_secs_f64();
    }
    let even = views.div_ceil(2);
    let color = sums[0]
        .iter()
        .zip(&sums[1])
        .map(|(a, b)| {
            let v = [0, 1, 2].map(|c| (a[c] + b[c]) / views as f32);
            [v[0], v[1], v[2], 1.0]
        })
        .collect();
    let half_color = sums[0]
        .iter()
        .map(|a| {
            [
                a[0] / even as f32,
                a[1] / even as f32,
                a[2] / even as f32,
                1.0,
            ]
        })
        .collect();
    Ok(ViewsImage {
        color,
        half_color,
        views,
        seconds_raster,
        seconds_accumulate,
    })
}

/// Adds one view to `sum`, each channel displaced by what the frustum did not carry:
/// its slope at the local scale plus the sphere correction, minus the `baked` shift (px).
fn accumulate(
    sum: &mut [[f32; 3]],
    view: &[[f32; 4]],
    (w, h): (usize, usize),
    maps: &LocalMaps,
    slopes: &[[f64; 2]],
    p: [f64; 2],
    baked: [f64; 2],
) {
    let slopes: Vec<[f32; 2]> = slopes.iter().map(|s| [s[0] as f32, s[1] as f32]).collect();
    let p = [p[0] as f32, p[1] as f32];
    let baked = [baked[0] as f32, baked[1] as f32];
    sum.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let i = y * w + x;
            let m = maps.slope[i];
            let s = maps.sphere[i];
            let sx = s[0] * p[0] + s[2] * p[1] - baked[0];
            let sy = s[1] * p[0] + s[3] * p[1] - baked[1];
            for (c, a) in slopes.iter().enumerate() {
                let dx = m[0] * a[0] + m[2] * a[1] + sx;
                let dy = m[1] * a[0] + m[3] * a[1] + sy;
                out[c] += bilinear(view, w, h, x as f32 - dx, y as f32 - dy, c);
            }
        }
    });
}

/// Channel `c` of `image` at pixel coordinates (x, y) (pixel centres at integers), clamped
/// to the edge.
fn bilinear(image: &[[f32; 4]], w: usize, h: usize, x: f32, y: f32, c: usize) -> f32 {
    let x = x.clamp(0.0, (w - 1) as f32);
    let y = y.clamp(0.0, (h - 1) as f32);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |xx: usize, yy: usize| image[yy * w + xx][c];
    let top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * fx;
    let bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * fx;
    top + (bottom - top) * fy
}
