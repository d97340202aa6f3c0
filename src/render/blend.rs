//! How fragments that reach one pixel combine: the settings every method shares.
//!
//! The seed paper composites every fragment front to back (C += (1 − A)·w·c, A += (1 − A)·w),
//! which lets the fragments of one surface occlude each other: a textured plane is then not
//! its own convolution. Here fragments are walked front to back in groups: a fragment whose
//! vergence lies within `group_tolerance_d` of the previous fragment reaching the same pixel
//! continues that pixel's group (one surface, or surfaces so close in depth that their blur is
//! the same), and a group adds its fragments' light linearly (colour Σw·c, coverage Σw).
//! Groups composite front to back by their coverage (at most 1), and the output is C / A.
//! A plane is then exactly its convolution, a point its PSF, and a sharp near object still
//! hides a blurred background (its group's coverage is 1 inside it).

use serde::{Deserialize, Serialize};

/// Which blend the runtime and the ground truth use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum BlendMode {
    /// Depth groups add linearly and composite front to back (conserves light).
    Grouped,
    /// The seed paper's per-fragment front-to-back compositing (kept for comparison).
    PerFragment,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlendSettings {
    pub mode: BlendMode,
    /// Largest vergence step (D) between consecutive fragments of one group.
    pub group_tolerance_d: f32,
    /// Vergence along each pixel's ray and kernels laid out with the pinhole's local scale
    /// (false: view-axis vergence and the centre's scale everywhere, as the seed paper).
    pub wide_field: bool,
    /// How a pixel a silhouette crosses enters the blend, where the frame says what lies
    /// behind the silhouette (rasterised scenes: `FrameInput::mixed`).
    #[serde(default)]
    pub edge_pixels: EdgePixels,
}

/// How a pixel a silhouette crosses enters the blend (docs/validation.md, "Mixed pixels").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum EdgePixels {
    /// One fragment: the pixel's mean colour at the near surface's depth, covering the whole
    /// pixel. What every method does.
    #[default]
    Whole,
    /// Two fragments: the near surface's colour over its share of the pixel's samples, and
    /// what lies behind the silhouette, at its own depth, over the rest. The reference only:
    /// measured against the multi-view truth it moved the edge band away from it in every
    /// case tried, so the splat does not split (docs/validation.md, "Mixed pixels").
    Split,
}

impl Default for BlendSettings {
    fn default() -> Self {
        BlendSettings {
            mode: BlendMode::Grouped,
            group_tolerance_d: DEFAULT_GROUP_TOLERANCE_D,
            wide_field: true,
            edge_pixels: EdgePixels::Whole,
        }
    }
}

/// Default group tolerance (D); docs/validation.md ("The blend") has the measurements.
pub const DEFAULT_GROUP_TOLERANCE_D: f32 = 0.05;

impl BlendSettings {
    /// The seed paper's blend and geometry (for comparisons and negative controls).
    pub fn paper() -> Self {
        BlendSettings {
            mode: BlendMode::PerFragment,
            group_tolerance_d: 0.0,
            wide_field: false,
            edge_pixels: EdgePixels::Whole,
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        if !(self.group_tolerance_d.is_finite() && (0.0..=10.0).contains(&self.group_tolerance_d)) {
            return Err(format!(
                "group tolerance {} D is outside 0 to 10 D",
                self.group_tolerance_d
            ));
        }
        Ok(())
    }
}

/// One pixel's blend state for one channel (the CPU methods' implementation).
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelBlend {
    color: f32,
    alpha: f32,
    group_color: f32,
    group_alpha: f32,
    last_dioptre: Option<f32>,
}

impl PixelBlend {
    /// Adds a fragment of colour `c` at vergence `dioptre` with kernel weight `w`.
    pub fn add(&mut self, settings: &BlendSettings, dioptre: f32, w: f32, c: f32) {
        match settings.mode {
            BlendMode::PerFragment => {
                self.color += (1.0 - self.alpha) * w * c;
                self.alpha += (1.0 - self.alpha) * w;
            }
            BlendMode::Grouped => {
                if self
                    .last_dioptre
                    .is_some_and(|last| (dioptre - last).abs() > settings.group_tolerance_d)
                {
                    self.close_group();
                }
                self.group_color += w * c;
                self.group_alpha += w;
                self.last_dioptre = Some(dioptre);
            }
        }
    }

    fn close_group(&mut self) {
        if self.group_alpha > 0.0 {
            // A group covers at most the whole pixel: more coverage (overlapping merged
            // blocks, kernel ripple) rescales its light instead of over-brightening.
            let scale = 1.0 / self.group_alpha.max(1.0);
            self.color += (1.0 - self.alpha) * self.group_color * scale;
            self.alpha += (1.0 - self.alpha) * self.group_alpha * scale;
        }
        self.group_color = 0.0;
        self.group_alpha = 0.0;
    }

    /// C / A (0 where nothing reached the pixel).
    pub fn resolve(mut self) -> f32 {
        self.close_group();
        if self.alpha > 0.0 {
            self.color / self.alpha
        } else {
            0.0
        }
    }

    /// C + (1 − A)·behind where something is known to lie behind the pixel
    /// ([`background_behind`]), else C / A.
    pub fn resolve_over(mut self, behind: Option<f32>) -> f32 {
        match behind {
            Some(b) => {
                self.close_group();
                self.color + (1.0 - self.alpha).max(0.0) * b
            }
            None => self.resolve(),
        }
    }
}

/// What lies behind pixel `(x, y)` of a one-layer frame, for the coverage its groups leave.
///
/// A single colour + depth layer does not say what a near fragment hides; dividing by the
/// coverage would fill that hole with the fragment's own light (a point light before a distant
/// background would gain up to a fifth of its energy). Behind a near surface lies the surface
/// that surrounds it from behind: along eight directions, past the first step to a farther
/// vergence (by more than `tolerance_d`) within the pixel's own blur reach
/// (`ceil(radius_px) + 1` steps: the hole is as wide as its kernel), as many pixels of that
/// surface as the reach (while its vergence runs on within the tolerance). Their mean colour
/// is the best guess of a texture whose continuation is hidden; `None` where there is no such
/// neighbour (a surface at the back; the frame's border keeps the division). The GPU's copy is
/// `background_behind` in glsl/common/blend.glsl.
pub fn background_behind(
    (width, height): (usize, usize),
    (x, y): (usize, usize),
    dioptre: &dyn Fn(usize) -> f32,
    color: &dyn Fn(usize) -> [f32; 3],
    radius_px: f32,
    tolerance_d: f32,
) -> Option<[f32; 3]> {
    const STEPS: [(i64, i64); 8] = [
        (1, 0),
        (1, 1),
        (0, 1),
        (-1, 1),
        (-1, 0),
        (-1, -1),
        (0, -1),
        (1, -1),
    ];
    let reach = radius_px.ceil() as i64 + 1;
    let own = dioptre(y * width + x);
    let (mut sum, mut found) = ([0.0f32; 3], 0i64);
    for (sx, sy) in STEPS {
        let mut previous = own;
        let mut surface: Option<f32> = None;
        let mut taken = 0i64;
        for s in 1..=2 * reach {
            let (qx, qy) = (x as i64 + s * sx, y as i64 + s * sy);
            if qx < 0 || qy < 0 || qx >= width as i64 || qy >= height as i64 {
                break;
            }
            let q = qy as usize * width + qx as usize;
            let v = dioptre(q);
            match surface {
                None => {
                    if s > reach {
                        break;
                    }
                    if previous - v <= tolerance_d {
                        previous = v;
                        continue;
                    }
                }
                Some(last) => {
                    if taken >= reach || (v - last).abs() > tolerance_d {
                        break;
                    }
                }
            }
            let c = color(q);
            for k in 0..3 {
                sum[k] += c[k];
            }
            taken += 1;
            surface = Some(v);
        }
        found += taken;
    }
    (found > 0).then(|| sum.map(|v| v / found as f32))
}
