//! Screen-space convolution kernels: the contract between the PSF precomputation (which fills
//! them) and the GPU runtime (which turns them into the per-frame PSF texture).
//!
//! For one (pupil, focus) state, every object distance `o` on a uniform dioptre axis has a
//! natural projected PSF radius per channel (in pixels, unrounded) and its PSF resampled to
//! EVERY radius level: at run time a fragment's radius is interpolated between neighbouring
//! object distances and then looked up at the two levels around it, so each PSF shape is
//! needed at radii other than its own.
//!
//! Radius levels step by a quarter pixel up to [`FINE_UNTIL_PX`] and by whole pixels beyond
//! (0, 0.25, …, 2, 3, …, Rmax): blending two kernels whose radii differ by a whole pixel is
//! fine for a blurred kernel, but below about 2 px the shapes of neighbouring integer radii
//! (a single texel and a 3×3 block) are too different for their mix to be the kernel between.
//! Level `l` has radius [`level_radius_px`] and a block of side 2·⌈radius⌉ + 1.
//!
//! Storage order follows the PSF texture (layer = level·No + o): blocks by level, then object
//! distance; within a block side² texels row-major, each an RGB triple (one channel per
//! wavelength), each channel normalised to sum 1 over the block.

/// A uniform axis of object vergences in dioptres (1/m): `min_d + i·step_d`, i < count.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DioptreAxis {
    pub min_d: f64,
    pub step_d: f64,
    pub count: usize,
}

impl DioptreAxis {
    /// `count` samples from `min_d` to `max_d` inclusive (one sample: `min_d`, step 1).
    pub fn spanning(min_d: f64, max_d: f64, count: usize) -> DioptreAxis {
        let step_d = if count > 1 {
            (max_d - min_d) / (count - 1) as f64
        } else {
            1.0
        };
        DioptreAxis {
            min_d,
            step_d,
            count,
        }
    }

    pub fn value_d(&self, index: usize) -> f64 {
        self.min_d + index as f64 * self.step_d
    }

    pub fn max_d(&self) -> f64 {
        self.value_d(self.count.saturating_sub(1))
    }

    /// Continuous index of `dioptres` on the axis, clamped to [0, count − 1].
    pub fn index_of(&self, dioptres: f64) -> f64 {
        ((dioptres - self.min_d) / self.step_d).clamp(0.0, (self.count.max(1) - 1) as f64)
    }
}

/// Number of texels in all blocks of radius below `r`: Σ_{q<r} (2q+1)² = r(4r² − 1)/3.
pub fn texels_below_radius(r: u32) -> usize {
    let r = r as usize;
    r * (4 * r * r).saturating_sub(1) / 3
}

/// Radius levels per pixel below [`FINE_UNTIL_PX`], and where whole-pixel levels begin.
/// (glsl/common/splat.glsl mirrors these.)
pub const LEVELS_PER_PX: u32 = 4;
pub const FINE_UNTIL_PX: u32 = 2;
const FINE_LEVELS: u32 = LEVELS_PER_PX * FINE_UNTIL_PX;

/// Number of radius levels for kernels up to `max_radius` px.
pub fn level_count(max_radius: u32) -> u32 {
    if max_radius <= FINE_UNTIL_PX {
        max_radius * LEVELS_PER_PX + 1
    } else {
        FINE_LEVELS + (max_radius - FINE_UNTIL_PX) + 1
    }
}

/// Kernel radius (px) of a level.
pub fn level_radius_px(level: u32) -> f64 {
    if level <= FINE_LEVELS {
        f64::from(level) / f64::from(LEVELS_PER_PX)
    } else {
        f64::from(FINE_UNTIL_PX + level - FINE_LEVELS)
    }
}

/// Radius of a level's block (its side is 2·radius + 1).
pub fn level_block_radius(level: u32) -> u32 {
    level_radius_px(level).ceil() as u32
}

/// Continuous level of a kernel radius: what the runtime interpolates on.
pub fn level_of_radius(radius_px: f64) -> f64 {
    let fine = f64::from(FINE_UNTIL_PX);
    if radius_px <= fine {
        radius_px * f64::from(LEVELS_PER_PX)
    } else {
        f64::from(FINE_LEVELS) + radius_px - fine
    }
}

/// Number of texels in the blocks of all levels below `level`.
pub fn texels_below_level(level: u32) -> usize {
    let side2 = |l: u32| kernel_side(level_block_radius(l)).pow(2);
    if level <= FINE_LEVELS + 1 {
        return (0..level).map(side2).sum();
    }
    // Whole-pixel levels have blocks of every radius from FINE_UNTIL_PX + 1 on.
    texels_below_level(FINE_LEVELS + 1) + texels_below_radius(level_block_radius(level))
        - texels_below_radius(FINE_UNTIL_PX + 1)
}

/// Side of the square kernel of radius `r`.
pub fn kernel_side(r: u32) -> usize {
    2 * r as usize + 1
}

/// The kernels of one (pupil, focus) state for all channels, object distances and radii.
#[derive(Clone, Debug, PartialEq)]
pub struct KernelSet {
    pub pupil_mm: f64,
    pub focus_d: f64,
    pub objects: DioptreAxis,
    pub max_radius_px: u32,
    /// Natural projected PSF radius in pixels, per object distance, per channel (R, G, B).
    pub radius_px: Vec<[f32; 3]>,
    /// All kernel texels in texture order (see the module documentation).
    pub texels: Vec<[f32; 3]>,
    /// Per object distance, the highest radius level its kernels hold: the blocks above are
    /// zero, since no fragment reads them (the band of levels a frame can read at that
    /// distance, [`super::grid`]); the last level where every level is held.
    pub top_level: Vec<u32>,
}

impl KernelSet {
    /// Texel count of a set with `objects` object distances and radii 0..=max_radius.
    pub fn texel_count(objects: usize, max_radius: u32) -> usize {
        objects * texels_below_level(level_count(max_radius))
    }

    /// A set of zeros, ready to be filled block by block.
    pub fn zeroed(
        pupil_mm: f64,
        focus_d: f64,
        objects: DioptreAxis,
        max_radius_px: u32,
    ) -> KernelSet {
        KernelSet {
            pupil_mm,
            focus_d,
            objects,
            max_radius_px,
            radius_px: vec![[0.0; 3]; objects.count],
            texels: vec![[0.0; 3]; Self::texel_count(objects.count, max_radius_px)],
            top_level: vec![level_count(max_radius_px) - 1; objects.count],
        }
    }

    /// Per object distance, the radius (px) of its highest held level: what the merge may
    /// give a block at that distance at most (glsl/render/splat/merge.comp).
    pub fn top_radius_px(&self) -> Vec<f32> {
        self.top_level
            .iter()
            .map(|&l| level_radius_px(l) as f32)
            .collect()
    }

    /// Index of the first texel of the block for radius `level` and object distance `object`.
    pub fn block_offset(&self, level: u32, object: usize) -> usize {
        let side = kernel_side(level_block_radius(level));
        self.objects.count * texels_below_level(level) + object * side * side
    }

    /// The block of a radius level (side 2·[`level_block_radius`] + 1).
    pub fn kernel(&self, level: u32, object: usize) -> &[[f32; 3]] {
        let start = self.block_offset(level, object);
        let side = kernel_side(level_block_radius(level));
        &self.texels[start..start + side * side]
    }

    pub fn kernel_mut(&mut self, level: u32, object: usize) -> &mut [[f32; 3]] {
        let start = self.block_offset(level, object);
        let side = kernel_side(level_block_radius(level));
        &mut self.texels[start..start + side * side]
    }

    /// Per object distance and channel, the radius of the uniform disc with the same r50 as
    /// the kernel at its natural radius (√2·r50, about the centroid): how blurred a kernel's
    /// core is. For a defocus disc it is the natural radius; for a PSF with a sharp core and a
    /// wide flare (coma, keratoconus) it is far smaller, and that core is what averaging a
    /// block of fragments would smear.
    pub fn core_radii_px(&self) -> Vec<[f32; 3]> {
        self.per_natural_kernel(|values, r| {
            std::f64::consts::SQRT_2 * encircled_radius(values, r, 0.5)
        })
    }

    /// Per object distance and channel, `of` one channel's kernel at its natural radius (its
    /// texels and the block radius of the level holding it).
    fn per_natural_kernel(&self, of: impl Fn(&[f64], u32) -> f64) -> Vec<[f32; 3]> {
        let levels = level_count(self.max_radius_px);
        (0..self.objects.count)
            .map(|o| {
                [0, 1, 2].map(|c| {
                    let natural = f64::from(self.radius_px[o][c]);
                    let level = (level_of_radius(natural).round() as u32)
                        .min(levels - 1)
                        .min(self.top_level[o]);
                    let values: Vec<f64> = self
                        .kernel(level, o)
                        .iter()
                        .map(|t| f64::from(t[c]))
                        .collect();
                    of(&values, level_block_radius(level)) as f32
                })
            })
            .collect()
    }

    /// Per object distance and channel, the radius of the uniform disc as high as the kernel's
    /// highest texel at its natural radius: 1/√(π·peak), the peak taken of the kernel
    /// normalised to unit sum. Averaging a block's colours moves a pixel by about the block's
    /// colour spread times its area times the height of the kernel's rim where that rim cuts
    /// the block (glsl/render/splat/merge.comp), and the highest rim a kernel has is its peak.
    /// For a defocus disc it is the natural radius, as the core radius is; for a line focus
    /// (astigmatism), a bright caustic ring or a sharp core it is smaller than the core radius,
    /// which counts a line of length L as a disc of diameter about L/√2 and so puts its height
    /// several times too low.
    pub fn peak_radii_px(&self) -> Vec<[f32; 3]> {
        self.per_natural_kernel(|values, _| {
            let sum: f64 = values.iter().sum();
            let peak = values.iter().copied().fold(0.0, f64::max);
            if sum <= 0.0 || peak <= 0.0 || !sum.is_finite() {
                return 0.5;
            }
            (1.0 / (std::f64::consts::PI * peak / sum)).sqrt()
        })
    }

    /// Bytes of the texels as stored for the GPU (three f32 per texel).
    pub fn size_bytes(&self) -> u64 {
        self.texels.len() as u64 * 12
    }

    /// Checks the invariants the runtime relies on; returns the first violation.
    pub fn validate(&self) -> Result<(), String> {
        if self.objects.count == 0 || self.objects.step_d.is_nan() || self.objects.step_d <= 0.0 {
            return Err(format!(
                "object axis {:?} is empty or not increasing",
                self.objects
            ));
        }
        if self.radius_px.len() != self.objects.count {
            return Err("one radius triple per object distance is required".into());
        }
        if self.texels.len() != Self::texel_count(self.objects.count, self.max_radius_px) {
            return Err("texel count does not match the object axis and maximum radius".into());
        }
        if let Some(bad) = self
            .radius_px
            .iter()
            .flatten()
            .find(|r| !r.is_finite() || **r < 0.0)
        {
            return Err(format!(
                "radius {bad} px is not a finite non-negative number"
            ));
        }
        if self.texels.iter().flatten().any(|v| !v.is_finite()) {
            return Err("kernel texels contain NaN or infinity".into());
        }
        let levels = level_count(self.max_radius_px);
        if self.top_level.len() != self.objects.count || self.top_level.iter().any(|&l| l >= levels)
        {
            return Err(format!(
                "one top radius level (below {levels}) per object distance is required"
            ));
        }
        Ok(())
    }
}

/// Radius about the centroid of a square kernel (side 2r + 1) within which `fraction` of its
/// energy lies, interpolated between pixel-centre distances (at least half a pixel).
pub fn encircled_radius(values: &[f64], r: u32, fraction: f64) -> f64 {
    let side = kernel_side(r);
    let total: f64 = values.iter().sum();
    if total <= 0.0 || !total.is_finite() {
        return 0.5;
    }
    let c = f64::from(r);
    let (mut mx, mut my) = (0.0, 0.0);
    for (i, v) in values.iter().enumerate() {
        mx += v * ((i % side) as f64 - c);
        my += v * ((i / side) as f64 - c);
    }
    let (mx, my) = (mx / total, my / total);
    let mut by_distance: Vec<(f64, f64)> = values
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let (x, y) = ((i % side) as f64 - c - mx, (i / side) as f64 - c - my);
            (x.hypot(y), v / total)
        })
        .collect();
    by_distance.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut acc, mut previous) = (0.0, 0.0);
    for (d, v) in by_distance {
        if acc + v >= fraction {
            let t = if v > 0.0 { (fraction - acc) / v } else { 1.0 };
            return (previous + t * (d - previous)).max(0.5);
        }
        acc += v;
        previous = d;
    }
    previous.max(0.5)
}

/// Kernels over a grid of (pupil, focus) states sharing one object axis and maximum radius.
#[derive(Clone, Debug, PartialEq)]
pub struct KernelGrid {
    pub pupils_mm: Vec<f64>,
    pub focus_d: Vec<f64>,
    pub wavelengths_nm: [f64; 3],
    pub objects: DioptreAxis,
    pub max_radius_px: u32,
    /// Vertical field of view and image height the kernels were projected for.
    pub fov_y_deg: f64,
    pub height_px: u32,
    /// Pupil-major: `sets[p * focus_d.len() + f]`.
    pub sets: Vec<KernelSet>,
}

/// Up to four grid sets and their bilinear weights for one (pupil, focus) state.
#[derive(Clone, Debug, PartialEq)]
pub struct GridBlend {
    pub corners: Vec<(usize, f64)>,
}

/// Position of `value` on a sorted axis: (lower index, upper index, fraction), clamped.
fn bracket(axis: &[f64], value: f64) -> (usize, usize, f64) {
    if axis.len() <= 1 || value <= axis[0] {
        return (0, 0, 0.0);
    }
    let last = axis.len() - 1;
    if value >= axis[last] {
        return (last, last, 0.0);
    }
    let upper = axis.partition_point(|&a| a <= value).min(last);
    let lower = upper - 1;
    let t = (value - axis[lower]) / (axis[upper] - axis[lower]);
    (lower, upper, t)
}

impl KernelGrid {
    pub fn set(&self, pupil_index: usize, focus_index: usize) -> &KernelSet {
        &self.sets[pupil_index * self.focus_d.len() + focus_index]
    }

    /// The sets around (pupil, focus) and their bilinear weights (clamped at the grid's edges;
    /// corners of weight zero are left out).
    pub fn blend(&self, pupil_mm: f64, focus_d: f64) -> GridBlend {
        let (p0, p1, tp) = bracket(&self.pupils_mm, pupil_mm);
        let (f0, f1, tf) = bracket(&self.focus_d, focus_d);
        let nf = self.focus_d.len();
        let mut corners: Vec<(usize, f64)> = Vec::with_capacity(4);
        for (p, wp) in [(p0, 1.0 - tp), (p1, tp)] {
            for (f, wf) in [(f0, 1.0 - tf), (f1, tf)] {
                let w = wp * wf;
                if w <= 0.0 {
                    continue;
                }
                let index = p * nf + f;
                match corners.iter_mut().find(|(i, _)| *i == index) {
                    Some(c) => c.1 += w,
                    None => corners.push((index, w)),
                }
            }
        }
        GridBlend { corners }
    }

    /// Natural radii blended like the kernels (what the fragment pass reads each frame).
    pub fn blended_radii(&self, blend: &GridBlend) -> Vec<[f32; 3]> {
        self.blend_objects(blend, |set| &self.sets[set].radius_px)
    }

    /// Per object distance, the radius of the highest level the blend holds (every corner
    /// holds it): the most a merged block's radius may be there.
    pub fn blended_top_radius_px(&self, blend: &GridBlend) -> Vec<f32> {
        let mut out = vec![f32::INFINITY; self.objects.count];
        for &(index, _) in &blend.corners {
            for (top, r) in out.iter_mut().zip(self.sets[index].top_radius_px()) {
                *top = top.min(r);
            }
        }
        out
    }

    /// Per-set values (one triple per object distance) blended like the kernels.
    pub fn blend_per_object(&self, blend: &GridBlend, per_set: &[Vec<[f32; 3]>]) -> Vec<[f32; 3]> {
        self.blend_objects(blend, |set| &per_set[set])
    }

    /// Σ over the blend's corners of weight × the corner set's per-object triples.
    fn blend_objects<'a>(
        &self,
        blend: &GridBlend,
        values: impl Fn(usize) -> &'a [[f32; 3]],
    ) -> Vec<[f32; 3]> {
        let mut out = vec![[0.0f32; 3]; self.objects.count];
        for &(index, w) in &blend.corners {
            for (o, r) in values(index).iter().enumerate() {
                for c in 0..3 {
                    out[o][c] += (w as f32) * r[c];
                }
            }
        }
        out
    }

    /// The blended set on the CPU (the GPU's PSF-texture pass does the same per frame).
    pub fn blended_set(&self, pupil_mm: f64, focus_d: f64) -> KernelSet {
        let blend = self.blend(pupil_mm, focus_d);
        let mut out = KernelSet::zeroed(pupil_mm, focus_d, self.objects, self.max_radius_px);
        out.radius_px = self.blended_radii(&blend);
        // a level the blend holds only where every corner holds it
        for &(index, _) in &blend.corners {
            for (top, &t) in out.top_level.iter_mut().zip(&self.sets[index].top_level) {
                *top = (*top).min(t);
            }
        }
        for &(index, w) in &blend.corners {
            for (dst, src) in out.texels.iter_mut().zip(&self.sets[index].texels) {
                for c in 0..3 {
                    dst[c] += w as f32 * src[c];
                }
            }
        }
        out
    }

    pub fn validate(&self) -> Result<(), String> {
        if self.sets.len() != self.pupils_mm.len() * self.focus_d.len() || self.sets.is_empty() {
            return Err("one kernel set per (pupil, focus) pair is required".into());
        }
        for axis in [&self.pupils_mm, &self.focus_d] {
            if axis.iter().any(|v| !v.is_finite()) || axis.windows(2).any(|w| w[1] <= w[0]) {
                return Err("pupil and focus axes must be strictly increasing".into());
            }
        }
        for set in &self.sets {
            if set.objects != self.objects || set.max_radius_px != self.max_radius_px {
                return Err(
                    "every set must share the grid's object axis and maximum radius".into(),
                );
            }
            set.validate()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_counts_match_a_direct_sum() {
        for r in 0..60u32 {
            let direct: usize = (0..r).map(|q| kernel_side(q) * kernel_side(q)).sum();
            assert_eq!(texels_below_radius(r), direct, "r = {r}");
        }
        // The paper's figure: Rmax 48, 41 object distances, 3 channels of f32 ≈ 74 MiB.
        let bytes = KernelSet::texel_count(41, 48) * 12;
        assert!(
            (bytes as f64 / (1 << 20) as f64 - 73.6).abs() < 0.5,
            "{bytes}"
        );
    }

    #[test]
    fn blocks_tile_the_texel_array_without_gaps() {
        let set = KernelSet::zeroed(4.0, 0.0, DioptreAxis::spanning(0.0, 2.0, 5), 6);
        let mut expected = 0;
        for level in 0..level_count(6) {
            for o in 0..5 {
                assert_eq!(set.block_offset(level, o), expected);
                expected += kernel_side(level_block_radius(level)).pow(2);
            }
        }
        assert_eq!(expected, set.texels.len());
        assert_eq!(level_count(6), 13);
        assert_eq!(level_radius_px(12), 6.0);
    }

    #[test]
    fn levels_step_by_quarter_pixels_then_whole_pixels() {
        let radii: Vec<f64> = (0..level_count(4)).map(level_radius_px).collect();
        assert_eq!(
            radii,
            [0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 3.0, 4.0]
        );
        for (l, r) in radii.iter().enumerate() {
            assert_eq!(level_of_radius(*r), l as f64);
        }
        assert_eq!(level_of_radius(2.5), 8.5);
        assert_eq!(level_of_radius(0.1), 0.4);
        // The closed form agrees with a direct sum at every level.
        for level in 0..60 {
            let direct: usize = (0..level)
                .map(|l| kernel_side(level_block_radius(l)).pow(2))
                .sum();
            assert_eq!(texels_below_level(level), direct, "level {level}");
        }
    }

    #[test]
    fn blend_weights_are_bilinear_and_sum_to_one() {
        let objects = DioptreAxis::spanning(0.0, 1.0, 2);
        let grid = KernelGrid {
            pupils_mm: vec![2.0, 4.0, 6.0],
            focus_d: vec![0.0, 2.0],
            wavelengths_nm: [612.0, 549.0, 464.0],
            objects,
            max_radius_px: 1,
            fov_y_deg: 60.0,
            height_px: 90,
            sets: (0..6)
                .map(|_| KernelSet::zeroed(0.0, 0.0, objects, 1))
                .collect(),
        };
        let b = grid.blend(5.0, 0.5);
        let total: f64 = b.corners.iter().map(|c| c.1).sum();
        assert!((total - 1.0).abs() < 1e-12);
        // pupil 5 = halfway 4..6 (indices 1, 2); focus 0.5 = quarter 0..2.
        let weight = |i: usize| {
            b.corners
                .iter()
                .find(|c| c.0 == i)
                .map(|c| c.1)
                .unwrap_or(0.0)
        };
        assert!((weight(2) - 0.5 * 0.75).abs() < 1e-12);
        assert!((weight(3) - 0.5 * 0.25).abs() < 1e-12);
        assert!((weight(4) - 0.5 * 0.75).abs() < 1e-12);
        // Exactly on a grid point: one corner.
        assert_eq!(grid.blend(4.0, 2.0).corners, vec![(3, 1.0)]);
        // Outside: clamped.
        assert_eq!(grid.blend(9.0, -1.0).corners, vec![(4, 1.0)]);
    }
}
