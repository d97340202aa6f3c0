//! The splat runtime's settings: tiles, texture format, merging, list memory, blend and early
//! exit.

use super::psf_texture::PsfTextureFormat;
use crate::render::blend::BlendSettings;

/// When and how strongly blurred blocks are merged into one fragment.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MergeSettings {
    /// 0 = off, 1 = 2×2 blocks, 2 = 2×2 and then 4×4 blocks, … up to [`MAX_MERGE_LEVELS`]
    /// (32×32).
    pub levels: u32,
    /// Level of detail by blur, k: a block of side s merges only when the kernels of all its
    /// pixels are at least k·s in radius, so a pixel is reached by at most about (2k + 1)²…
    /// (4k + 1)² fragments per merged surface however large the blur. 0: any side (the seed
    /// paper's rule, which lets a 32×32 block merge under a 5 px kernel). Each merged block
    /// reads its pixels' kernel summed over the block, so what merging averages is only the
    /// pixels' colours and depths, which the other tolerances bound.
    pub blur_per_block: f32,
    /// Smallest blur radius (px, over the block and the channels) for a block to merge.
    pub min_radius_px: f32,
    /// The most, as a fraction of [`MergeSettings::white`], that averaging one block's colours
    /// may change any pixel it reaches. Under a kernel of radius r the block's pixels keep their kernel and
    /// only their colours are averaged; a PSF's sharp rim crossing a block of side s whose
    /// halves differ by Δc misplaces about Δc·s²/4 pixels' worth of colour difference at a
    /// height of 1/(πr²), so a block merges when Δc ≤ 4π·ε·(r/s)². A colour gradient cancels
    /// around the rim; a step, or a texture whose period is near s, does not.
    pub color_error: f32,
    /// The linear value the image is shown as white (2^−EV of the exposure it is displayed
    /// at): the unit of `color_error`. 1 for display-referred values; a front door sets it
    /// from the exposure it writes or judges the image at (`display_white`), since a scene's
    /// colours are in cd/m² and its white lies at hundreds of them (colonnade: 880). Read
    /// every frame, so it may change between frames without rebuilding anything.
    #[serde(default = "one")]
    pub white: f32,
    /// Largest summed pairwise dioptre difference in a block, per pair and pixel of blur.
    pub dioptre_tolerance: f32,
    /// In the wide field, where a merged block makes one read (the radius levels, or the
    /// per-fragment blend), the most (px) that read may misplace its edge pixels' kernels: the
    /// block's pixels lie c·δ apart in kernel space (c = cos²θ, the local radial shrink) while
    /// the read assumes δ, so a block of side s merges only where (1 − c)·s/2 is at most this.
    /// True PSFs vary texel to texel: without this bound, 2×2 blocks off by 0.1–0.4 px put a
    /// two-pixel pattern into colonnade's blurred lamps. With the layer kernels and depth
    /// groups a merged block reads its pixels where they lie (`block_reads` in
    /// glsl/common/splat.glsl), and this does not apply.
    pub scale_error_px: f32,
}

impl MergeSettings {
    /// Blocks up to 32×32 where colours allow (docs/validation.md, "Merging").
    pub const DEFAULT_LEVELS: u32 = 5;
    /// No block wider than half the blur: with blocks as wide as the blur (k = 1),
    /// colonnade/astigmatism at 1280×720 lost 2.5 dB against 2×2 blocks; with k = 2 it gains
    /// 1.2 dB.
    pub const DEFAULT_BLUR_PER_BLOCK: f32 = 2.0;
    /// A quarter of an 8-bit step of the white, shared by the blocks along a kernel's rim: the
    /// bound holds per block, and a rim crosses 2π·r/s of them, at least 4π ≈ 12.6 where no
    /// block is wider than half the blur (k = 2), so each gets a sixteenth. On a texture whose
    /// period is near the block side they all meet it (a sinusoid plane under a 12–19 px blur,
    /// merged up to 32×32, loses 2–12 dB at 1/255 and nothing at 1/1020). Measured against the
    /// exact reference at 1280×720, colonnade / astigmatism: −0.13 dB and 2.5× fewer kernel
    /// evaluations than the same bound applied in cd/m² (docs/validation.md, "The colour
    /// rule's unit").
    pub const DEFAULT_COLOR_ERROR: f32 = 1.0 / 16320.0;
    /// `--quality fast`'s bound: a whole 8-bit step of the white shared by the blocks along a
    /// kernel's rim, which crosses 2π·r/s of them, at least 2π where blocks are as wide as the
    /// blur (k = 1): 1/(255·2π) ≈ 1/1602. Applied per block (1/255), chart / myopia lost 10 dB
    /// against `balanced` at 640×360, where this loses 2 (docs/quality.md).
    pub const FAST_COLOR_ERROR: f32 = 1.0 / (255.0 * std::f32::consts::TAU);
    /// docs/validation.md, "Merging in the wide field".
    pub const DEFAULT_SCALE_ERROR_PX: f32 = 0.02;
}

fn one() -> f32 {
    1.0
}

/// The linear value an exposure of `exposure_ev` stops shows as white (linear × 2^EV = 1).
pub fn display_white(exposure_ev: f32) -> f32 {
    (-exposure_ev).exp2()
}

impl Default for MergeSettings {
    fn default() -> Self {
        // The minimum radius and dioptre tolerance are the seed paper's; the levels, the block
        // width and the colour bound are this engine's (see their constants).
        MergeSettings {
            levels: MergeSettings::DEFAULT_LEVELS,
            blur_per_block: MergeSettings::DEFAULT_BLUR_PER_BLOCK,
            min_radius_px: 5.0,
            color_error: MergeSettings::DEFAULT_COLOR_ERROR,
            white: 1.0,
            dioptre_tolerance: 0.01,
            scale_error_px: MergeSettings::DEFAULT_SCALE_ERROR_PX,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SplatSettings {
    /// Screen tile side in pixels: 8, 16 or 32.
    pub tile_size: u32,
    pub texture_format: PsfTextureFormat,
    pub merge: MergeSettings,
    /// Upper bound on the tile-list buffer (bytes); bands are used beyond it. The device's
    /// storage-buffer binding limit applies as well.
    pub max_list_bytes: u64,
    /// Upper bound on one binding of the fragment buffer (bytes); the device's limit applies
    /// as well. A frame whose fragments exceed it is bound as up to four ranges.
    pub max_fragment_binding_bytes: u64,
    /// How fragments combine, and the wide-field geometry.
    pub blend: BlendSettings,
    /// The convolution stops walking a tile's list once every pixel's coverage reaches
    /// 1 − ε in every channel (0 = never): what lies behind then adds at most ε of its light.
    pub saturation_epsilon: f32,
    /// Steady-state frames in one submission with the PSF texture kept while the eye's state
    /// holds (false: every frame plans its lists and rebuilds the texture, as before; kept as
    /// the baseline `ocular bench --baseline` measures against).
    pub steady_state: bool,
    /// A hidden-layer fragment lends light only through the part of the pupil that sees it
    /// past the nearer surfaces (false: wherever nearer depth groups leave coverage, as
    /// before; kept as the control `tests/it/layers.rs` measures against).
    pub pupil_visibility: bool,
    /// How the convolution walks a tile's list (the same image either way).
    pub convolve_walk: ConvolveWalk,
    /// Read each object distance's own kernel (one filtered read per pixel and fragment, all
    /// channels) where neighbouring distances' radii differ by at most
    /// [`LAYER_RADIUS_STEP_MAX_PX`], on axis; false: always the radius levels (up to three).
    pub layer_kernels: bool,
}

/// The speed/accuracy ladder a user picks from (`--quality`); the expert options (`--merge-*`,
/// `--level-kernels`, …) refine the preset they start from. docs/quality.md measures the trade.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Quality {
    /// No approximation the engine can avoid: no merging, no early exit. What the tests judge
    /// the others against; its cost grows as pixels × blur².
    Exact,
    /// Merges blocks only where the averaged colours cannot show (a quarter of an 8-bit step
    /// shared along a kernel's rim) and no block is wider than half the blur: within 0.5 dB of
    /// `exact` (0.00–0.13 dB measured, docs/quality.md).
    #[default]
    Balanced,
    /// Merges blocks as wide as the blur from 1.5 px of blur on, wherever colours agree to an
    /// 8-bit step shared along the rim (a colour rule about 10× looser than `balanced`'s):
    /// docs/quality.md measures its speed and its error against the exact reference.
    Fast,
}

impl Quality {
    /// The settings the preset starts from.
    pub fn settings(self) -> SplatSettings {
        let base = SplatSettings::default();
        match self {
            Quality::Exact => SplatSettings {
                merge: MergeSettings {
                    levels: 0,
                    ..base.merge
                },
                saturation_epsilon: 0.0,
                ..base
            },
            Quality::Balanced => base,
            Quality::Fast => SplatSettings {
                merge: MergeSettings {
                    blur_per_block: 1.0,
                    min_radius_px: 1.5,
                    color_error: MergeSettings::FAST_COLOR_ERROR,
                    ..base.merge
                },
                ..base
            },
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Quality::Exact => "exact",
            Quality::Balanced => "balanced",
            Quality::Fast => "fast",
        }
    }
}

/// Largest radius step (px) between neighbouring object distances at which the layer kernels
/// are used: the filter between two distances then blends kernels whose edges lie at most this
/// far apart, where the radius levels blend kernels a whole pixel apart (above 2 px).
pub const LAYER_RADIUS_STEP_MAX_PX: f32 = 0.5;

/// The convolution's two shapes (glsl/render/splat/convolve.comp and convolve_visits.comp):
/// the same image, each fast on one kind of device.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ConvolveWalk {
    /// Visits on a CPU implementation, pixels on a GPU.
    #[default]
    Auto,
    /// Every pixel of a tile over every fragment, branching past what a fragment does not need.
    Pixels,
    /// Planned reads in shared memory, each visited by the subgroups whose pixels it reaches.
    Visits,
}

impl ConvolveWalk {
    /// Whether the visits walk runs on a device of this kind.
    pub fn visits_on(self, kind: crate::gpu::DeviceKind) -> bool {
        match self {
            ConvolveWalk::Auto => kind == crate::gpu::DeviceKind::Cpu,
            ConvolveWalk::Pixels => false,
            ConvolveWalk::Visits => true,
        }
    }
}

impl Default for SplatSettings {
    fn default() -> Self {
        SplatSettings {
            tile_size: 8,
            texture_format: PsfTextureFormat::Auto,
            merge: MergeSettings::default(),
            max_list_bytes: 1 << 30,
            max_fragment_binding_bytes: u64::MAX,
            blend: BlendSettings::default(),
            saturation_epsilon: DEFAULT_SATURATION_EPSILON,
            steady_state: true,
            pupil_visibility: true,
            layer_kernels: true,
            convolve_walk: ConvolveWalk::Auto,
        }
    }
}

/// Most merge levels: blocks up to 2^5 = 32 pixels on a side.
pub const MAX_MERGE_LEVELS: u32 = 5;

/// Default early-exit threshold of the convolution.
pub const DEFAULT_SATURATION_EPSILON: f32 = 1e-3;

impl SplatSettings {
    pub fn validate(&self) -> Result<(), String> {
        if ![8, 16, 32].contains(&self.tile_size) {
            return Err(format!(
                "tile size {} is not one of 8, 16, 32",
                self.tile_size
            ));
        }
        if self.merge.levels > MAX_MERGE_LEVELS {
            return Err(format!(
                "merge levels {} is outside 0 to {MAX_MERGE_LEVELS}",
                self.merge.levels
            ));
        }
        if !(self.merge.blur_per_block.is_finite()
            && (0.0..=64.0).contains(&self.merge.blur_per_block))
        {
            return Err(format!(
                "merge blur per block {} is outside 0 to 64",
                self.merge.blur_per_block
            ));
        }
        if !(self.merge.min_radius_px >= 0.0
            && self.merge.color_error >= 0.0
            && self.merge.dioptre_tolerance >= 0.0
            && self.merge.scale_error_px >= 0.0)
        {
            return Err("merge thresholds must be non-negative numbers".into());
        }
        if !(self.merge.white.is_finite() && self.merge.white > 0.0) {
            return Err(format!(
                "the display white {} must be a positive number (an exposure within ±64 EV)",
                self.merge.white
            ));
        }
        if !(self.saturation_epsilon.is_finite() && (0.0..0.5).contains(&self.saturation_epsilon)) {
            return Err(format!(
                "saturation epsilon {} is outside 0 to 0.5",
                self.saturation_epsilon
            ));
        }
        self.blend.validate()
    }
}
