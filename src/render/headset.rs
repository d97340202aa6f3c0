//! Head-mounted displays a binocular pair can be rendered for: each eye's frame at the
//! headset's panel size and field of view, and the refresh interval both eyes must fit in.
//!
//! Each eye's frame is a symmetric pinhole frustum: the vertical field below, the horizontal
//! one following from the panel's aspect. A real headset's per-eye frustum is asymmetric (it
//! reaches farther towards the temple than towards the nose) and its lens distorts it; the
//! runtime reports it per device and per user (OpenXR's `xrLocateViews`). What is rendered
//! here is the optics of the eye looking at an undistorted image of that size and field,
//! which is what a simulation of the wearer's eye needs, not a frame to send to the panel.
//! docs/binocular.md lists the published figures each preset comes from.

use crate::scene::Scene;

/// A headset preset (`--headset`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Headset {
    /// Meta Quest 3: 2064×2208 per eye, 96° vertical field, 90 Hz.
    Quest3,
    /// HTC Vive Pro: 1440×1600 per eye, 110° field (taken as vertical), 90 Hz.
    VivePro,
}

/// What a preset fixes.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HeadsetSpec {
    pub name: &'static str,
    /// One eye's panel, pixels.
    pub width_px: u32,
    pub height_px: u32,
    /// The vertical field of one eye's frame (degrees).
    pub fov_y_deg: f64,
    /// The default refresh rate (Hz): both eyes' frames within 1/refresh.
    pub refresh_hz: f64,
}

impl Headset {
    pub fn spec(self) -> HeadsetSpec {
        match self {
            // Meta's figures: two 2064×2208 LCD panels, 110° horizontal × 96° vertical field
            // (both eyes together; the vertical one is each eye's), 90 Hz by default (120 Hz
            // experimental).
            Headset::Quest3 => HeadsetSpec {
                name: "Meta Quest 3",
                width_px: 2064,
                height_px: 2208,
                fov_y_deg: 96.0,
                refresh_hz: 90.0,
            },
            // HTC's figures: two 1440×1600 AMOLED panels (2880×1600 together), 90 Hz, and the
            // 110° field of the original Vive's lenses, which HTC quotes as horizontal for both
            // eyes together. Each eye's panel is taller than it is wide, so 110° is taken as
            // the vertical field of one eye (a horizontal field of 104° then follows).
            Headset::VivePro => HeadsetSpec {
                name: "HTC Vive Pro",
                width_px: 1440,
                height_px: 1600,
                fov_y_deg: 110.0,
                refresh_hz: 90.0,
            },
        }
    }
}

/// What `--json` reports of a headset a frame was rendered for.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HeadsetSummary {
    pub preset: Headset,
    pub name: &'static str,
    pub width_px: u32,
    pub height_px: u32,
    pub fov_y_deg: f64,
    pub fov_x_deg: f64,
    pub refresh_hz: f64,
    pub frame_budget_ms: f64,
}

impl Headset {
    pub fn summary(self) -> HeadsetSummary {
        let s = self.spec();
        HeadsetSummary {
            preset: self,
            name: s.name,
            width_px: s.width_px,
            height_px: s.height_px,
            fov_y_deg: s.fov_y_deg,
            fov_x_deg: s.fov_x_deg(),
            refresh_hz: s.refresh_hz,
            frame_budget_ms: s.frame_budget_ms(),
        }
    }
}

impl HeadsetSpec {
    pub fn size(&self) -> (u32, u32) {
        (self.width_px, self.height_px)
    }

    /// `scene` as one eye of this headset sees it, and the frame's size: its camera at the
    /// headset's vertical field ([`Scene::with_fov_y_deg`]) and the panel's pixels.
    pub fn frame(&self, scene: Scene) -> (Scene, (u32, u32)) {
        (scene.with_fov_y_deg(self.fov_y_deg), self.size())
    }

    /// One eye's horizontal field (degrees): the pinhole's, from the panel's aspect.
    pub fn fov_x_deg(&self) -> f64 {
        let half_y = (0.5 * self.fov_y_deg).to_radians().tan();
        let aspect = f64::from(self.width_px) / f64::from(self.height_px);
        2.0 * (half_y * aspect).atan().to_degrees()
    }

    /// The time both eyes' frames must fit in (ms).
    pub fn frame_budget_ms(&self) -> f64 {
        1000.0 / self.refresh_hz
    }

    /// Pixels per degree at the frame's centre.
    pub fn centre_px_per_deg(&self) -> f64 {
        let focal_px = 0.5 * f64::from(self.height_px) / (0.5 * self.fov_y_deg).to_radians().tan();
        focal_px * 1f64.to_radians()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    #[test]
    fn each_preset_is_a_frame_the_renderer_accepts() {
        for h in Headset::value_variants() {
            let s = h.spec();
            assert!(crate::limits::FOV_Y_DEG.contains(s.fov_y_deg), "{s:?}");
            assert!(s.width_px > 0 && s.height_px > 0 && s.refresh_hz > 0.0);
        }
    }

    #[test]
    fn the_horizontal_field_follows_the_panel_aspect() {
        // Vive Pro: tan(52°)·… — a square panel would give 110° both ways; 1440/1600 = 0.9 of
        // tan 55° = 1.4281 is 1.2853, 2·atan of which is 104.23°.
        let v = Headset::VivePro.spec();
        assert!((v.fov_x_deg() - 104.23).abs() < 0.01, "{}", v.fov_x_deg());
        // Quest 3: 2064/2208 of tan 48° = 1.1106 is 1.0382 → 92.15°.
        let q = Headset::Quest3.spec();
        assert!((q.fov_x_deg() - 92.15).abs() < 0.01, "{}", q.fov_x_deg());
        // 90 Hz: both eyes within 11.1 ms (the headset budget).
        assert!((q.frame_budget_ms() - 11.111).abs() < 1e-3);
        // Quest 3 at the centre: 1104 / tan 48° = 994.1 px per radian, 17.35 px per degree.
        assert!(
            (q.centre_px_per_deg() - 17.35).abs() < 0.01,
            "{}",
            q.centre_px_per_deg()
        );
    }
}
