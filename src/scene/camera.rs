//! The pinhole camera: pose as position + yaw/pitch (world +Y up, no roll), and the matrices
//! the rasteriser needs.
//!
//! World space is right-handed, metres, +Y up. At yaw = pitch = 0 the camera looks along −Z;
//! positive yaw turns left (counter-clockwise seen from above), positive pitch looks up.

use glam::{DMat4, DVec3, DVec4};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position_m: [f64; 3],
    pub yaw_deg: f64,
    pub pitch_deg: f64,
    /// Vertical field of view.
    pub fov_y_deg: f64,
    pub near_m: f64,
    pub far_m: f64,
}

/// Pitch is kept off the poles, where yaw (and the up vector) would be undefined.
pub const MAX_PITCH_DEG: f64 = 89.9;

impl Camera {
    /// Unit view direction.
    pub fn forward(&self) -> [f64; 3] {
        let (yaw, pitch) = (self.yaw_deg.to_radians(), self.pitch_deg.to_radians());
        [
            -yaw.sin() * pitch.cos(),
            pitch.sin(),
            -yaw.cos() * pitch.cos(),
        ]
    }

    /// Yaw and pitch (degrees) that look along `direction` (need not be unit length).
    pub fn angles_towards(direction: [f64; 3]) -> Option<(f64, f64)> {
        let d = DVec3::from(direction);
        let length = d.length();
        if !length.is_finite() || length <= 1e-12 {
            return None;
        }
        let d = d / length;
        let pitch = d.y.clamp(-1.0, 1.0).asin().to_degrees();
        let yaw = if d.x.abs() < 1e-15 && d.z.abs() < 1e-15 {
            0.0
        } else {
            (-d.x).atan2(-d.z).to_degrees()
        };
        Some((yaw, pitch.clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG)))
    }

    /// World → view (camera at the origin looking along −Z, +Y up).
    pub fn view_matrix(&self) -> DMat4 {
        DMat4::look_to_rh(
            DVec3::from(self.position_m),
            DVec3::from(self.forward()),
            DVec3::Y,
        )
    }

    /// View → clip for a `aspect` = width / height frame: Vulkan clip space with +Y down (so
    /// row 0 of the image is the top), and reversed Z (near → 1, far → 0) for uniform
    /// relative depth precision.
    pub fn projection_matrix(&self, aspect: f64) -> DMat4 {
        let f = 1.0 / (self.fov_y_deg.to_radians() * 0.5).tan();
        let (n, far) = (self.near_m, self.far_m);
        let a = n / (far - n);
        let b = n * far / (far - n);
        DMat4::from_cols(
            DVec4::new(f / aspect, 0.0, 0.0, 0.0),
            DVec4::new(0.0, -f, 0.0, 0.0),
            DVec4::new(0.0, 0.0, a, -1.0),
            DVec4::new(0.0, 0.0, b, 0.0),
        )
    }

    /// Pixels per radian at the image centre for a frame `height_px` tall.
    pub fn focal_length_px(&self, height_px: u32) -> f64 {
        0.5 * f64::from(height_px) / (self.fov_y_deg.to_radians() * 0.5).tan()
    }
}
