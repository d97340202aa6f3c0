//! CPU implementations of each splat step, written from the specification in
//! src/render/splat/ (not from the shaders), to check the GPU passes one by one.

use ocular::render::splat::{Fragment, MergeSettings};

pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub tile: u32,
    pub dioptre_min: f32,
    pub dioptre_step: f32,
    pub max_radius: u32,
    /// Focal length in pixels for the wide-field geometry; 0 = the centre's scale everywhere
    /// and view-axis vergence.
    pub focal_px: f32,
    /// The blend's depth-group tolerance (D): a merged block lies within one group.
    pub group_tolerance_d: f32,
    /// Whether merged blocks read their pixels where they lie in kernel space (the layer
    /// kernels with the depth-group blend), so that the wide field does not bound merging.
    pub block_reads: bool,
}

impl Frame {
    /// Distance along the ray over view-axis depth at a screen point.
    pub fn ray_factor(&self, x: f32, y: f32) -> f32 {
        if self.focal_px <= 0.0 {
            return 1.0;
        }
        let u = (x - 0.5 * self.width as f32) / self.focal_px;
        let v = (y - 0.5 * self.height as f32) / self.focal_px;
        (1.0 + u * u + v * v).sqrt()
    }

    /// cos θ of the direction through a screen point (1 without the wide-field geometry).
    pub fn cos_theta(&self, x: f32, y: f32) -> f32 {
        if self.focal_px <= 0.0 {
            return 1.0;
        }
        let u = x - 0.5 * self.width as f32;
        let v = y - 0.5 * self.height as f32;
        let rho = (u * u + v * v).sqrt();
        if rho < 1e-6 {
            return 1.0;
        }
        self.focal_px / (self.focal_px * self.focal_px + rho * rho).sqrt()
    }
}

pub fn fragments(
    frame: &Frame,
    color: &[[f32; 4]],
    depth: &[f32],
    radii: &[[f32; 3]],
) -> Vec<Fragment> {
    let last = (radii.len() - 1) as f32;
    (0..frame.width * frame.height)
        .map(|i| {
            let d = depth[i as usize];
            let finite = d > 0.0 && d.is_finite();
            let center = [
                (i % frame.width) as f32 + 0.5,
                (i / frame.width) as f32 + 0.5,
            ];
            // Light arrives with the vergence of the distance along the pixel's ray.
            let distance = d * frame.ray_factor(center[0], center[1]);
            let dioptre = if finite { 1.0 / distance } else { 0.0 };
            let index = ((dioptre - frame.dioptre_min) / frame.dioptre_step).clamp(0.0, last);
            let i0 = index.floor() as usize;
            let i1 = (i0 + 1).min(radii.len() - 1);
            let t = index - i0 as f32;
            let radius = [0, 1, 2].map(|c| {
                (radii[i0][c] * (1.0 - t) + radii[i1][c] * t).min(frame.max_radius as f32)
            });
            let c = color[i as usize];
            Fragment {
                color: [c[0], c[1], c[2]],
                depth: if finite { distance } else { 3.0e38 },
                radius,
                index,
                center,
                size: 1,
                dioptre,
            }
        })
        .collect()
}

/// One merge level (block `size` 2, 4, …) following the rules in merge.comp.
/// `core`: per object distance, the smallest core radius over the channels (merge.comp).
pub fn merge_level(
    frame: &Frame,
    fragments: &mut [Fragment],
    settings: &MergeSettings,
    core: &[f32],
    peak: &[f32],
    size: u32,
) {
    let at = |table: &[f32], f: &Fragment| {
        let i0 = f.index.floor() as usize;
        let i1 = (i0 + 1).min(table.len() - 1);
        let t = f.index - i0 as f32;
        table[i0] * (1.0 - t) + table[i1] * t
    };
    let core_of = |f: &Fragment| at(core, f);
    let child = size / 2;
    let w = frame.width;
    for by in 0..frame.height / size {
        for bx in 0..w / size {
            let o = (by * size) * w + bx * size;
            let ids = [o, o + child, o + child * w, o + child * w + child].map(|i| i as usize);
            let f: Vec<Fragment> = ids.iter().map(|&i| fragments[i]).collect();
            if f.iter().any(|x| x.size != child) {
                continue;
            }
            let r_min = f
                .iter()
                .flat_map(|x| x.radius.into_iter().chain([core_of(x)]))
                .fold(f32::INFINITY, f32::min);
            if r_min
                < settings
                    .min_radius_px
                    .max(settings.blur_per_block * size as f32)
            {
                continue;
            }
            // Off the centre the block's pixels lie cos²θ·δ apart in kernel space; unless they
            // are read where they lie, the one read assumes δ: the edge pixels' misplacement is
            // bounded.
            let centre = (
                (bx * size) as f32 + 0.5 * size as f32,
                (by * size) as f32 + 0.5 * size as f32,
            );
            let c = frame.cos_theta(centre.0, centre.1).powi(2);
            if !frame.block_reads && (1.0 - c) * 0.5 * size as f32 > settings.scale_error_px {
                continue;
            }
            let (lo, hi) = f
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(x.dioptre), hi.max(x.dioptre))
                });
            if hi - lo > frame.group_tolerance_d {
                continue;
            }
            // 4π·ε·(r/s)² with r the smaller of the blur and the kernels' peak radius, in
            // merge.comp's order of operations.
            let r_peak = f.iter().map(|x| at(peak, x)).fold(f32::INFINITY, f32::min);
            let blur_per_side = r_min.min(r_peak) / size as f32;
            let color_bound = 12.566371f32
                * (settings.color_error * settings.white)
                * blur_per_side
                * blur_per_side;
            let mut ok = true;
            let mut spread = 0.0f32;
            for a in 0..4 {
                for b in a + 1..4 {
                    let dc = (0..3)
                        .map(|c| (f[a].color[c] - f[b].color[c]).abs())
                        .fold(0.0, f32::max);
                    if dc > color_bound {
                        ok = false;
                    }
                    spread += (f[a].index - f[b].index).abs() * frame.dioptre_step;
                }
            }
            if !ok || spread >= 6.0 * settings.dioptre_tolerance * r_min {
                continue;
            }
            let mut m = f[0];
            m.color = [0, 1, 2].map(|c| 0.25 * f.iter().map(|x| x.color[c]).sum::<f32>());
            m.depth = f.iter().map(|x| x.depth).fold(f32::INFINITY, f32::min);
            m.index = 0.25 * f.iter().map(|x| x.index).sum::<f32>();
            m.dioptre = 0.25 * f.iter().map(|x| x.dioptre).sum::<f32>();
            // Every block keeps its children's kernel: a 2×2 block reads it half a pixel off the
            // grid (the bilinear lookup sums it over the four pixels), a larger one reads its
            // block-summed kernel.
            m.radius = [0, 1, 2].map(|c| f.iter().map(|x| x.radius[c]).fold(0.0, f32::max));
            m.center = [
                (bx * size) as f32 + 0.5 * size as f32,
                (by * size) as f32 + 0.5 * size as f32,
            ];
            m.size = size;
            fragments[ids[0]] = m;
            for &i in &ids[1..] {
                fragments[i].size = 0;
            }
        }
    }
}

/// The pixels a fragment's kernel can reach: those whose offset d from its centre maps to a
/// kernel offset k = J·d with |k.x| and |k.y| below the kernel's bound (the square of its
/// texels, read bilinearly, or of its block), where J is the local scale (I where none
/// applies). Off the centre of a wide frame this is a parallelogram on the screen.
pub fn reached_pixels(frame: &Frame, f: &Fragment) -> Vec<[i64; 2]> {
    let radius = f.radius.iter().fold(0.0f32, |a, &b| a.max(b));
    let r = radius.ceil();
    // Off the centre a kernel of radius ≥ 0.5 px shrinks by (cos²θ, cos θ) radially and
    // tangentially (in full from 1.5 px).
    let c = frame.cos_theta(f.center[0], f.center[1]);
    let t = (radius - 0.5).clamp(0.0, 1.0);
    let (cr, ct) = (1.0 + t * (c * c - 1.0), 1.0 + t * (c - 1.0));
    let scaled = cr < 1.0;
    let (j11, j12, j22) = if scaled {
        let u = f.center[0] - 0.5 * frame.width as f32;
        let v = f.center[1] - 0.5 * frame.height as f32;
        let rho = (u * u + v * v).sqrt();
        let (ex, ey) = (u / rho, v / rho);
        (
            ct + (cr - ct) * ex * ex,
            (cr - ct) * ex * ey,
            ct + (cr - ct) * ey * ey,
        )
    } else {
        (1.0, 0.0, 1.0)
    };
    let wide_block = scaled && frame.block_reads;
    let side = f.size as f32;
    let bound = if f.size >= 4 {
        // a block-summed kernel, (2r + s)² texels; in the wide field the box (s/2)·(J₁₁, J₂₂)
        // moved over the plain kernel's texels
        r + 0.5 + 0.5 * side * if wide_block { j11.max(j22) } else { 1.0 }
    } else if f.size == 2 && wide_block {
        // four reads at J·(±½, ±½)
        r + 1.0 + 0.5 * (j12.abs() + j11.abs().max(j22.abs()))
    } else {
        r + 1.0
    };
    // J shrinks no offset by more than cos²θ: a square that surely holds the footprint.
    let half = (bound / cr).ceil() as i64 + 1;
    let (cx, cy) = (f.center[0].floor() as i64, f.center[1].floor() as i64);
    let mut pixels = Vec::new();
    for py in (cy - half).max(0)..=(cy + half).min(frame.height as i64 - 1) {
        for px in (cx - half).max(0)..=(cx + half).min(frame.width as i64 - 1) {
            let dx = px as f32 + 0.5 - f.center[0];
            let dy = py as f32 + 0.5 - f.center[1];
            let (kx, ky) = (j11 * dx + j12 * dy, j12 * dx + j22 * dy);
            if kx.abs() < bound && ky.abs() < bound {
                pixels.push([px, py]);
            }
        }
    }
    pixels
}

/// Continuous radius level: quarter pixels up to 2 px, whole pixels beyond (the PSF texture's
/// levels).
fn level_of_radius(r: f32) -> f32 {
    if r <= 2.0 {
        4.0 * r
    } else {
        8.0 + r - 2.0
    }
}

/// Filtered texture reads the pixel walk makes for one (pixel, fragment) pair of `f` on axis,
/// at most: the layer texture's one read, or four for a merged block in the wide field, which
/// reads where its pixels lie; with the radius levels, one per level the channels' radii span
/// when that is at most three, else two per channel (one where it sits on a level).
pub fn reads_per_evaluation(frame: &Frame, f: &Fragment, layered: bool) -> u64 {
    let radius = f.radius.iter().fold(0.0f32, |a, &b| a.max(b));
    if layered {
        let c = frame.cos_theta(f.center[0], f.center[1]);
        let shrinks = radius > 0.5 && c < 1.0;
        return if shrinks && f.size > 1 && frame.block_reads {
            4
        } else {
            1
        };
    }
    let levels = f.radius.map(level_of_radius);
    let base = levels
        .iter()
        .map(|l| l.floor())
        .fold(f32::INFINITY, f32::min);
    let top = levels.iter().map(|l| l.ceil()).fold(0.0f32, f32::max);
    if top - base <= 2.0 {
        1 + (top - base) as u64
    } else {
        levels
            .iter()
            .map(|l| if l.fract() > 0.0 { 2 } else { 1 })
            .sum()
    }
}

/// Per tile, the sorted (depth bits, fragment index) list.
pub fn tile_lists(frame: &Frame, fragments: &[Fragment]) -> Vec<Vec<[u32; 2]>> {
    let t = frame.tile as i64;
    let tiles_x = frame.width.div_ceil(frame.tile) as usize;
    let tiles_y = frame.height.div_ceil(frame.tile) as usize;
    let mut lists = vec![Vec::new(); tiles_x * tiles_y];
    for (i, f) in fragments.iter().enumerate() {
        if f.size == 0 {
            continue;
        }
        let mut tiles: Vec<usize> = reached_pixels(frame, f)
            .iter()
            .map(|&[px, py]| (py / t) as usize * tiles_x + (px / t) as usize)
            .collect();
        tiles.sort_unstable();
        tiles.dedup();
        for tile in tiles {
            lists[tile].push([f.depth.max(0.0).to_bits(), i as u32]);
        }
    }
    for list in &mut lists {
        list.sort_unstable();
    }
    lists
}
