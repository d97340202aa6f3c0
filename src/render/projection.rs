//! The pinhole frame's geometry, shared by every method: where each pixel looks, how far along
//! its ray a view-axis depth lies, and how an angular kernel is laid out on the screen there.
//!
//! Input depth is measured along the view axis (Blender's Z pass); light from a point reaches
//! the eye with the vergence of its distance along the ray, which is longer off axis by
//! sec θ = √(1 + (u² + v²)/f²) (u, v the pixel centre's offset from the image centre, f the
//! focal length in pixels). A pinhole maps an angle δ at direction θ to δ·f/cos²θ pixels
//! radially and δ·f/cos θ tangentially, while kernels are laid out at the centre's scale f:
//! a screen offset d from a fragment maps to the kernel offset
//! k = cos θ·d + (cos²θ − cos θ)(d·e)e (e the radial unit vector), and the kernel's weight per
//! screen pixel is its weight per kernel pixel times cos³θ (the Jacobian's determinant), so
//! the light a fragment spreads is conserved.
//!
//! Kernels are pixel-integrated at the centre's scale and read between texels (bilinearly),
//! which widens a kernel by a tent of one texel: harmless for a blurred kernel, but it would
//! smear an in-focus one (a single texel) over its neighbours, while the true screen kernel
//! of a PSF far smaller than a pixel is that one pixel at any scale. So the map is applied in
//! full to kernels of radius >= 1.5 px and not at all below 0.5 px, linearly between
//! ([`LocalScale::for_radius`]). The map is a continuous function of the field angle and the
//! radius: there is no threshold under which it is skipped, since a kernel that switches
//! between exact texel reads and bilinear ones draws a visible circle around the centre.

/// A frame's projection: its size in pixels and vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    pub width: u32,
    pub height: u32,
    pub fov_y_deg: f64,
}

/// The local layout of a kernel at one screen position: radial unit vector and cos θ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalScale {
    pub radial: [f64; 2],
    pub cos_theta: f64,
}

impl LocalScale {
    /// The identity (the image centre, or a frame treated as narrow).
    pub const CENTRE: LocalScale = LocalScale {
        radial: [1.0, 0.0],
        cos_theta: 1.0,
    };

    /// Radial and tangential shrink (kernel pixels per screen pixel) for a kernel of
    /// `radius_px`: (cos²θ, cos θ) from 1.5 px up, (1, 1) below 0.5 px, linear between.
    pub fn for_radius(&self, radius_px: f64) -> [f64; 2] {
        let t = (radius_px - 0.5).clamp(0.0, 1.0);
        let c = self.cos_theta;
        [1.0 + t * (c * c - 1.0), 1.0 + t * (c - 1.0)]
    }

    /// How far (whole pixels, per screen axis) a kernel of block radius `r` read at the
    /// local scale can reach. Bilinear reads reach one texel past the block, so the kernel is
    /// non-zero for kernel offsets inside the square of half-side r + 1; screen offsets are its
    /// image under the inverse map (1/c_t)·I + (1/c_r − 1/c_t)·e·eᵀ, whose extent along a grid
    /// axis is the largest row sum of its absolute values.
    pub fn reach_px(&self, r: u32, radius_px: f64) -> u32 {
        let [cr, ct] = self.for_radius(radius_px);
        if cr < 1.0 {
            let a = 1.0 / cr - 1.0 / ct;
            let [ex, ey] = self.radial;
            let along = (ex * ex).max(ey * ey) + (ex * ey).abs();
            ((f64::from(r) + 1.0) * (1.0 / ct + a * along)).ceil() as u32 - 1
        } else {
            r
        }
    }

    /// Kernel offset (centre-scale pixels) of a screen offset `d` (pixels), for a kernel
    /// of `radius_px`.
    pub fn kernel_offset(&self, d: [f64; 2], radius_px: f64) -> [f64; 2] {
        let [cr, ct] = self.for_radius(radius_px);
        let along = (d[0] * self.radial[0] + d[1] * self.radial[1]) * (cr - ct);
        [
            ct * d[0] + along * self.radial[0],
            ct * d[1] + along * self.radial[1],
        ]
    }

    /// Kernel weight per screen pixel over kernel weight per kernel pixel (the map's
    /// determinant; cos³θ in full).
    pub fn area_factor(&self, radius_px: f64) -> f64 {
        let [cr, ct] = self.for_radius(radius_px);
        cr * ct
    }
}

impl Projection {
    /// Focal length in pixels: (H/2)/tan(fov_y/2).
    pub fn focal_px(&self) -> f64 {
        0.5 * self.height as f64 / (0.5 * self.fov_y_deg.to_radians()).tan()
    }

    /// Offset (pixels) of a screen point from the image centre.
    fn offset(&self, x_px: f64, y_px: f64) -> [f64; 2] {
        [
            x_px - 0.5 * self.width as f64,
            y_px - 0.5 * self.height as f64,
        ]
    }

    /// Distance along the ray over depth along the view axis, at a screen point (pixel
    /// coordinates; a pixel's centre is x + 0.5).
    pub fn ray_over_axial(&self, x_px: f64, y_px: f64) -> f64 {
        let [u, v] = self.offset(x_px, y_px);
        let f = self.focal_px();
        (1.0 + (u * u + v * v) / (f * f)).sqrt()
    }

    /// Distance along the ray of pixel (x, y) whose view-axis depth is `depth_m`; `None` for
    /// depth that is not a positive finite number (optical infinity).
    pub fn ray_distance_m(&self, x: u32, y: u32, depth_m: f32) -> Option<f64> {
        (depth_m > 0.0 && depth_m.is_finite()).then(|| {
            f64::from(depth_m) * self.ray_over_axial(f64::from(x) + 0.5, f64::from(y) + 0.5)
        })
    }

    /// Object vergence (D) of pixel (x, y): 1 / distance along its ray; 0 at infinity.
    pub fn dioptre_at(&self, x: u32, y: u32, depth_m: f32) -> f64 {
        self.ray_distance_m(x, y, depth_m).map_or(0.0, |d| 1.0 / d)
    }

    /// Vergence of every pixel of a row-major depth buffer of this frame's size.
    pub fn dioptres(&self, depth_m: &[f32]) -> Vec<f64> {
        let w = self.width.max(1);
        depth_m
            .iter()
            .enumerate()
            .map(|(i, &d)| self.dioptre_at(i as u32 % w, i as u32 / w, d))
            .collect()
    }

    /// The kernel layout at a screen point (pixel coordinates).
    pub fn local_scale(&self, x_px: f64, y_px: f64) -> LocalScale {
        let [u, v] = self.offset(x_px, y_px);
        let rho = u.hypot(v);
        let f = self.focal_px();
        if rho < 1e-9 {
            return LocalScale::CENTRE;
        }
        LocalScale {
            radial: [u / rho, v / rho],
            cos_theta: f / f.hypot(rho),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wall_corner_at_50_degrees_is_138_percent_farther_along_its_ray() {
        // The figure: 16:9, 50° vertical field, corners 1.38× the axial depth.
        let p = Projection {
            width: 1600,
            height: 900,
            fov_y_deg: 50.0,
        };
        let corner = p.ray_over_axial(0.0, 0.0);
        let t = (25f64).to_radians().tan();
        let expected = (1.0 + t * t * (1.0 + (16.0f64 / 9.0).powi(2))).sqrt();
        assert!((corner - expected).abs() < 1e-12);
        assert!((corner - 1.38).abs() < 0.01, "{corner}");
        // A wall at 5 m: 0.200 D on the axis, 0.145 D in the corner.
        assert!((p.dioptre_at(0, 0, 5.0) - 0.145).abs() < 0.001);
    }

    #[test]
    fn the_local_scale_is_the_pinhole_jacobian() {
        let p = Projection {
            width: 641,
            height: 361,
            fov_y_deg: 60.0,
        };
        let f = p.focal_px();
        // A direction 35° to the right of the axis, on the horizontal centre line.
        let theta = 35f64.to_radians();
        let x = 320.5 + f * theta.tan();
        let s = p.local_scale(x, 180.5);
        // Radial: a small angle δ moves f·δ/cos²θ pixels; tangential: f·δ/cos θ.
        let delta = 1e-6;
        let radial_px = f * ((theta + delta).tan() - theta.tan());
        let k = s.kernel_offset([radial_px, 0.0], 10.0);
        assert!((k[0] - f * delta).abs() < 1e-6 * f * delta * 1e3, "{k:?}");
        let tangential_px = f * delta / theta.cos();
        let k = s.kernel_offset([0.0, tangential_px], 10.0);
        assert!((k[1] - f * delta).abs() < 1e-9, "{k:?}");
        assert!((s.area_factor(10.0) - theta.cos().powi(3)).abs() < 1e-12);
        // An in-focus kernel keeps its own pixel.
        assert_eq!(s.kernel_offset([1.0, 0.0], 0.2), [1.0, 0.0]);
    }
}
