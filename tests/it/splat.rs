//! The tiled PSF-splatting runtime on lavapipe, against CPU references: the PSF texture against
//! the CPU blend of the kernel grid, each pass against a CPU implementation of its step, and
//! whole frames against the ground-truth renderer.

use crate::common;

use common::pixels::{max_rgb_difference, opaque_pixels, psnr};
use common::splat_cpu;
use common::synthetic::{ExactSynthetic, SyntheticEye, NO_MERGE};
use ocular::gpu::texture_probe::TextureProbe;
use ocular::gpu::Context;
use ocular::psf::{
    kernel_side, level_block_radius, level_count, level_of_radius, level_radius_px, DioptreAxis,
    KernelGrid,
};
use ocular::render::reference;
use ocular::render::splat::{
    FrameInput, MergeSettings, PsfTextureFormat, SplatOutput, SplatSettings, Splatter, ViewState,
};

struct Scene {
    width: u32,
    height: u32,
    color: Vec<[f32; 4]>,
    depth: Vec<f32>,
}

impl Scene {
    fn new(width: u32, height: u32, f: impl Fn(u32, u32) -> ([f32; 3], f32)) -> Scene {
        let (color, depth) = opaque_pixels(width, height, f);
        Scene {
            width,
            height,
            color,
            depth,
        }
    }

    fn input(&self) -> FrameInput<'_> {
        FrameInput {
            width: self.width,
            height: self.height,
            color: &self.color,
            depth_m: &self.depth,
            fov_y_deg: 60.0,
            hidden_layers: &[],
            mixed: None,
        }
    }
}

fn axis_for(eye: &SyntheticEye, min_d: f64, max_d: f64, count: usize) -> (DioptreAxis, u32) {
    let axis = DioptreAxis::spanning(min_d, max_d, count);
    let max_radius = (0..count)
        .flat_map(|o| (0..3).map(move |c| (o, c)))
        .map(|(o, c)| eye.radius_px(c, axis.value_d(o), 4.0))
        .fold(0.0f64, f64::max)
        .ceil() as u32;
    (axis, max_radius)
}

fn splat(
    ctx: &Context,
    grid: &KernelGrid,
    settings: SplatSettings,
    scene: &Scene,
    keep: bool,
) -> SplatOutput {
    let mut splatter = Splatter::new(ctx, grid.clone(), settings).unwrap();
    splatter
        .render(
            &scene.input(),
            ViewState {
                pupil_mm: 4.0,
                focus_d: grid.focus_d[0],
            },
            keep,
        )
        .unwrap()
}

/// Smooth, textured colour in [0.05, 0.95].
fn texture(x: u32, y: u32, seed: f32) -> [f32; 3] {
    let (x, y) = (x as f32, y as f32);
    [
        0.5 + 0.45 * (0.21 * x + seed).sin(),
        0.5 + 0.45 * (0.17 * y + 0.5 * seed).cos(),
        0.5 + 0.45 * ((x + y) * 0.09 + 2.0 * seed).sin(),
    ]
}

/// The PSF texture read at `points` (texel centres) against `wanted`: the worst error relative
/// to max(|wanted|, 1). The probe is returned so that the caller drops it with its splatter.
fn worst_texel_error(
    ctx: &Context,
    image: &ocular::gpu::Image,
    sampler: &ocular::gpu::Sampler,
    points: &[[f32; 3]],
    wanted: &[[f32; 3]],
) -> (f32, TextureProbe) {
    let probe = TextureProbe::new(ctx).unwrap();
    let samples = probe.sample(ctx, image, sampler, points).unwrap();
    let mut worst = 0.0f32;
    for (want, s) in wanted.iter().zip(&samples) {
        for c in 0..3 {
            worst = worst.max((want[c] - s[c]).abs() / want[c].abs().max(1.0));
        }
    }
    (worst, probe)
}

#[test]
fn psf_texture_matches_cpu_blend_of_four_grid_states() {
    let ctx = common::gpu();
    let objects = DioptreAxis::spanning(0.0, 2.0, 5);
    let max_radius = 6;
    let mut eye = SyntheticEye::new(0.5, 2.5);
    eye.pupil_scale = true;
    let mut sets = Vec::new();
    for pupil in [2.0, 6.0] {
        for focus in [0.5, 1.5] {
            eye.focus_d = [focus - 0.1, focus, focus + 0.2];
            let mut set = eye.kernel_set(objects, max_radius, pupil);
            set.focus_d = focus;
            sets.push(set);
        }
    }
    let grid = KernelGrid {
        pupils_mm: vec![2.0, 6.0],
        focus_d: vec![0.5, 1.5],
        wavelengths_nm: [612.0, 549.0, 464.0],
        objects,
        max_radius_px: max_radius,
        fov_y_deg: 60.0,
        height_px: 90,
        sets,
    };
    let view = ViewState {
        pupil_mm: 3.0,
        focus_d: 0.75,
    };
    assert_eq!(grid.blend(view.pupil_mm, view.focus_d).corners.len(), 4);
    let expected = grid.blended_set(view.pupil_mm, view.focus_d);
    let scene = Scene::new(16, 16, |_, _| ([0.5; 3], 2.0));
    for (format, tolerance) in [
        (PsfTextureFormat::Rgba32Float, 1e-5),
        (PsfTextureFormat::Rgba16Float, 2e-3),
    ] {
        let settings = SplatSettings {
            texture_format: format,
            merge: NO_MERGE,
            ..SplatSettings::default()
        };
        let mut splatter = Splatter::new(&ctx, grid.clone(), settings).unwrap();
        splatter.render(&scene.input(), view, false).unwrap();
        let (image, sampler) = splatter.psf_texture();
        assert_eq!(
            image.extent()[2] as usize,
            objects.count,
            "one layer per object"
        );
        // Every level's block and its ring of zeros, at every object distance, read texel by
        // texel where the atlas says the block lies.
        let mut points = Vec::new();
        let mut wanted = Vec::new();
        for level in 0..level_count(max_radius) {
            let r = level_block_radius(level) as i64;
            let [cx, cy] = splatter.psf_texture_centre(0, level);
            for o in 0..objects.count {
                for dy in -r - 1..=r + 1 {
                    for dx in -r - 1..=r + 1 {
                        let (x, y) = (cx as i64 + dx, cy as i64 + dy);
                        points.push([x as f32 + 0.5, y as f32 + 0.5, o as f32 + 0.5]);
                        wanted.push(if dx.abs() <= r && dy.abs() <= r {
                            let side = kernel_side(r as u32);
                            let texel = expected.kernel(level, o)
                                [(dy + r) as usize * side + (dx + r) as usize];
                            texel.map(|v| v * (side * side) as f32)
                        } else {
                            [0.0; 3]
                        });
                    }
                }
            }
        }
        let (worst, probe) = worst_texel_error(&ctx, image, sampler, &points, &wanted);
        eprintln!("{format:?}: worst relative texel error {worst:.2e}");
        assert!(worst < tolerance, "{format:?}: {worst}");
        drop((splatter, probe));
    }
    common::finish(ctx);
}

/// A merged block of 4×4 pixels and up reads its level's kernel summed over the block's
/// pixels: every such texel the atlas holds equals the sum, written here from the blended
/// kernel texel by texel (the block's pixels at ±½ … ±(s − 1)/2 from its centre), divided by
/// s² and stored at the level's (2r+1)² scale, with its ring of zeros.
#[test]
fn block_kernels_are_the_kernel_summed_over_the_block() {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(0.3, 4.0);
    let (objects, max_radius) = axis_for(&eye, 0.0, 3.0, 5);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let view = ViewState {
        pupil_mm: 4.0,
        focus_d: 0.3,
    };
    let expected = grid.blended_set(view.pupil_mm, view.focus_d);
    let settings = SplatSettings {
        texture_format: PsfTextureFormat::Rgba32Float,
        merge: MergeSettings {
            levels: 4,
            blur_per_block: 0.0,
            min_radius_px: 2.0,
            ..MergeSettings::default()
        },
        ..SplatSettings::default()
    };
    let mut splatter = Splatter::new(&ctx, grid.clone(), settings).unwrap();
    splatter
        .render(
            &Scene::new(16, 16, |_, _| ([0.5; 3], 2.0)).input(),
            view,
            false,
        )
        .unwrap();
    let (image, sampler) = splatter.psf_texture();
    let (mut points, mut wanted) = (Vec::new(), Vec::new());
    let mut held = 0;
    for side in [4i64, 8, 16] {
        for level in 0..level_count(max_radius) {
            let Some([cx, cy]) = splatter.psf_texture_block_centre(0, level, side as u32) else {
                assert!(
                    level_radius_px(level) < 2.0,
                    "level {level} of side {side} missing"
                );
                continue;
            };
            held += 1;
            let r = level_block_radius(level) as i64;
            let k = kernel_side(r as u32);
            let edge = r + side / 2; // texels on either side of the centre
            for o in [0, objects.count - 1] {
                let kernel = expected.kernel(level, o);
                for ty in -edge - 1..=edge {
                    for tx in -edge - 1..=edge {
                        // texel (cx + tx) holds offset tx + ½ from the block's centre
                        let mut sum = [0.0f64; 3];
                        for jy in 0..side {
                            for jx in 0..side {
                                // pixel j at j − (s − 1)/2: integer kernel offset t − j + s/2
                                let (kx, ky) = (tx - jx + side / 2, ty - jy + side / 2);
                                if kx.abs() <= r && ky.abs() <= r {
                                    let v = kernel[((ky + r) * k as i64 + kx + r) as usize];
                                    for c in 0..3 {
                                        sum[c] += f64::from(v[c]);
                                    }
                                }
                            }
                        }
                        let scale = (k * k) as f64 / (side * side) as f64;
                        let ring = tx == -edge - 1 || ty == -edge - 1 || tx == edge || ty == edge;
                        points.push([
                            (cx as i64 + tx) as f32 + 0.5,
                            (cy as i64 + ty) as f32 + 0.5,
                            o as f32 + 0.5,
                        ]);
                        wanted.push(if ring {
                            [0.0; 3]
                        } else {
                            sum.map(|v| (v * scale) as f32)
                        });
                    }
                }
            }
        }
    }
    assert!(held >= 3 * 4, "{held} block kernels held");
    let (worst, probe) = worst_texel_error(&ctx, image, sampler, &points, &wanted);
    eprintln!("{held} block kernels: worst relative texel error {worst:.2e}");
    assert!(worst < 1e-5, "{worst}");
    drop((splatter, probe));
    common::finish(ctx);
}

/// A merged block in the wide field reads the kernel's mean over its box from the plain layer
/// kernel's summed-area table (glsl/common/layer_atlas.glsl, layer_box): four filtered reads
/// at the box's corners. Each box is checked against the plain kernel's texels read back and
/// integrated over the box on the CPU (each texel a unit square, weighted by its overlap):
/// boxes of ½ to 9 px half-sides, inside, across and past the kernel's edge. Negative control:
/// the same integral with the box half a texel off (the corner convention one step wrong).
#[test]
fn layer_boxes_are_the_kernel_integrated_over_the_box() {
    let ctx = common::gpu();
    let mut eye = SyntheticEye::new(1.0, 4.0);
    eye.pupil_scale = true;
    // 1/32 D steps: fine enough for the layer kernels
    let objects = DioptreAxis::spanning(0.0, 3.0, 97);
    let grid = eye.grid(objects, 12, &[4.0], 90);
    let mut splatter = Splatter::new(&ctx, grid, SplatSettings::default()).unwrap();
    let view = ViewState {
        pupil_mm: 4.0,
        focus_d: 1.0,
    };
    let out = splatter
        .render(
            &Scene::new(16, 16, |_, _| ([0.5; 3], 0.5)).input(),
            view,
            false,
        )
        .unwrap();
    assert!(
        out.stats.layer_kernels,
        "the frame should read the layer kernels"
    );
    let sums = splatter.layer_sums().expect("layer kernels");
    let (image, sampler) = (sums.image, sums.sampler);
    let (plain, table) = (sums.plain_texel, sums.table_texel);
    let r = sums.max_radius_px as i64;
    let side = (2 * r + 1) as usize;
    let probe = TextureProbe::new(&ctx).unwrap();
    let mut bits = common::xorshift(0x5a7);
    let mut uniform = move || (bits() >> 11) as f64 / (1u64 << 53) as f64;
    let (mut worst, mut control) = (0.0f64, f64::INFINITY);
    for o in [5usize, 48, 96] {
        let layer = o as f32 + 0.5;
        // the plain kernel's texels, offsets −R … R
        let centres: Vec<[f32; 3]> = (-r..=r)
            .flat_map(|y| (-r..=r).map(move |x| (x, y)))
            .map(|(x, y)| {
                let at = |p: u32, t: i64| (p as i64 + t) as f32 + 0.5;
                [at(plain[0], x), at(plain[1], y), layer]
            })
            .collect();
        let texels = probe.sample(&ctx, image, sampler, &centres).unwrap();
        let total: f64 = texels.iter().map(|t| f64::from(t[1])).sum();
        assert!(total > 0.0, "object {o}: an empty kernel proves nothing");
        // The kernel's integral over a box, each texel a unit square.
        let integral = |u: [f64; 2], h: [f64; 2]| -> [f64; 3] {
            let mut sum = [0.0; 3];
            for (i, t) in texels.iter().enumerate() {
                let (x, y) = ((i % side) as f64 - r as f64, (i / side) as f64 - r as f64);
                let overlap =
                    |c: f64, lo: f64, hi: f64| ((c + 0.5).min(hi) - (c - 0.5).max(lo)).max(0.0);
                let w = overlap(x, u[0] - h[0], u[0] + h[0]) * overlap(y, u[1] - h[1], u[1] + h[1]);
                for c in 0..3 {
                    sum[c] += w * f64::from(t[c]);
                }
            }
            sum
        };
        for _ in 0..200 {
            let u = [0, 1].map(|_| (uniform() * 2.0 - 1.0) * (r as f64 + 3.0));
            let h = [0, 1].map(|_| 0.5 + 8.5 * uniform());
            // four corners, clamped to the table as layer_box clamps them
            let b = r as f64 + 0.5;
            let lo = [0, 1].map(|a| (u[a] - h[a]).clamp(-b, b));
            let hi = [0, 1].map(|a| (u[a] + h[a]).clamp(-b, b));
            let corner = |x: f64, y: f64| {
                let at = |p: u32, v: f64| (p as f64 + v + r as f64 + 1.0) as f32;
                [at(table[0], x), at(table[1], y), layer]
            };
            let reads = probe
                .sample(
                    &ctx,
                    image,
                    sampler,
                    &[
                        corner(hi[0], hi[1]),
                        corner(lo[0], hi[1]),
                        corner(hi[0], lo[1]),
                        corner(lo[0], lo[1]),
                    ],
                )
                .unwrap();
            let want = integral(u, h);
            let off = integral([u[0] + 0.5, u[1]], h);
            for c in 0..3 {
                let got = f64::from(reads[0][c]) - f64::from(reads[1][c]) - f64::from(reads[2][c])
                    + f64::from(reads[3][c]);
                worst = worst.max((got - want[c]).abs() / total);
                if (off[c] - want[c]).abs() > 1e-3 * total {
                    control = control.min((got - off[c]).abs() / total);
                }
            }
        }
    }
    eprintln!("box reads: worst error {worst:.2e} of the kernel's sum; half a texel off: {control:.2e} at least");
    assert!(worst < BOX_BAR, "{worst:.2e}");
    assert!(control > BOX_BAR, "negative control passed: {control:.2e}");
    drop((splatter, probe));
    common::finish(ctx);
}

/// Error of a box read as a fraction of the kernel's sum (single floats, filtered reads).
/// Measured on lavapipe: 1.76e-6 at worst; half a texel off, 1.02e-3 at least.
const BOX_BAR: f64 = 1e-5;

#[test]
fn blurred_point_over_sharp_background_renders_as_its_kernel() {
    let ctx = common::gpu();
    let mut eye = SyntheticEye::new(0.5, 3.0);
    eye.focus_d = [0.5; 3];
    let (objects, max_radius) = axis_for(&eye, 0.5, 4.5, 9);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let (px, py, point_depth) = (40u32, 30u32, 1.0 / 2.8f32);
    let white = [1.0, 0.8, 0.6];
    // The background is in focus (0.5 D): its kernel is a single texel of weight 1.
    let scene = Scene::new(80, 60, |x, y| {
        if (x, y) == (px, py) {
            (white, point_depth)
        } else {
            ([0.0; 3], 2.0)
        }
    });
    let out = splat(
        &ctx,
        &grid,
        SplatSettings {
            merge: NO_MERGE,
            ..SplatSettings::default()
        },
        &scene,
        false,
    );
    let set = &grid.sets[0];
    let dioptre = 1.0 / f64::from(point_depth);
    let index = objects.index_of(dioptre);
    let (o0, t) = (index.floor() as usize, (index - index.floor()) as f32);
    let o1 = (o0 + 1).min(objects.count - 1);
    let mut worst = 0.0f32;
    let mut peak = 0.0f32;
    for (c, &white_c) in white.iter().enumerate() {
        let radius = set.radius_px[o0][c] * (1.0 - t) + set.radius_px[o1][c] * t;
        // The two radius levels around the radius, blended by the fraction between them.
        let level = level_of_radius(f64::from(radius));
        let (r0, r1, tr) = (
            level.floor() as u32,
            level.ceil() as u32,
            (level - level.floor()) as f32,
        );
        let weight_at = |l: u32, dx: i64, dy: i64| -> f32 {
            let r = level_block_radius(l);
            if dx.abs() > r as i64 || dy.abs() > r as i64 {
                return 0.0;
            }
            let side = kernel_side(r);
            let i = (dy + r as i64) as usize * side + (dx + r as i64) as usize;
            set.kernel(l, o0)[i][c] * (1.0 - t) + set.kernel(l, o1)[i][c] * t
        };
        for y in 0..60i64 {
            for x in 0..80i64 {
                let (dx, dy) = (x - px as i64, y - py as i64);
                let w = weight_at(r0, dx, dy) * (1.0 - tr) + weight_at(r1, dx, dy) * tr;
                // The point's group covers w of each pixel and the black in-focus background
                // the rest, so the pixels show its kernel; at its own pixel, where the single
                // layer holds nothing behind the point, the background around it fills the
                // rest (before, C / A returned the point's colour there: it gained light).
                let want = w * white[c];
                let got = out.color[(y * 80 + x) as usize][c];
                peak = peak.max(w * white_c);
                worst = worst.max((got - want).abs());
            }
        }
    }
    eprintln!("point kernel: worst |splat − kernel| = {worst:.2e} (kernel peak {peak:.3})");
    assert!(
        worst < 2e-3 * peak.max(1e-3) + 1e-5,
        "worst {worst}, peak {peak}"
    );
    common::finish(ctx);
}

#[test]
fn uniform_plane_renders_uniform_and_conserves_energy() {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(0.2, 4.0);
    let (objects, max_radius) = axis_for(&eye, 0.0, 3.0, 13);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let colour = [0.3, 0.55, 0.8];
    let scene = Scene::new(160, 90, |_, _| (colour, 0.5));
    for merge in [NO_MERGE, MergeSettings::default()] {
        let out = splat(
            &ctx,
            &grid,
            SplatSettings {
                merge,
                ..SplatSettings::default()
            },
            &scene,
            false,
        );
        let worst = out
            .color
            .iter()
            .flat_map(|p| (0..3).map(move |c| (p[c] - colour[c]).abs() / colour[c]))
            .fold(0.0, f32::max);
        let energy_in: f64 = scene
            .color
            .iter()
            .map(|p| f64::from(p[0] + p[1] + p[2]))
            .sum();
        let energy_out: f64 = out
            .color
            .iter()
            .map(|p| f64::from(p[0] + p[1] + p[2]))
            .sum();
        eprintln!(
            "merge levels {}: worst relative deviation {worst:.2e}, live fragments {}",
            merge.levels, out.stats.live_fragments
        );
        assert!(worst < 1e-3, "{worst}");
        assert!((energy_out / energy_in - 1.0).abs() < 1e-3);
    }
    common::finish(ctx);
}

fn layered_scene() -> Scene {
    // Background at 0.4 D, a mid plane at 1.5 D, a near square at 3 D, an infinitely far strip.
    Scene::new(160, 90, |x, y| {
        if (70..110).contains(&x) && (20..55).contains(&y) {
            (texture(x, y, 2.0), 1.0 / 3.0)
        } else if (20..90).contains(&x) && (35..80).contains(&y) {
            (texture(x, y, 1.0), 1.0 / 1.5)
        } else if y < 8 {
            ([0.9, 0.9, 0.2], f32::INFINITY)
        } else {
            (texture(x, y, 0.0), 1.0 / 0.4)
        }
    })
}

#[test]
fn layered_scene_matches_ground_truth() {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(0.4, 3.0);
    // 0.125 D steps: the synthetic shapes change quickly with dioptres.
    let (objects, max_radius) = axis_for(&eye, 0.0, 4.0, 33);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let scene = layered_scene();
    let truth = reference::render(
        &scene.input(),
        &ExactSynthetic {
            eye: eye.clone(),
            pupil_mm: 4.0,
            max_radius,
        },
    );
    for (label, settings) in [
        ("defaults", SplatSettings::default()),
        (
            "no merge",
            SplatSettings {
                merge: NO_MERGE,
                ..SplatSettings::default()
            },
        ),
        (
            "rgba32f",
            SplatSettings {
                texture_format: PsfTextureFormat::Rgba32Float,
                ..SplatSettings::default()
            },
        ),
    ] {
        let out = splat(&ctx, &grid, settings, &scene, false);
        let db = psnr(&out.color, &truth);
        eprintln!(
            "layered scene, {label}: PSNR vs ground truth {db:.2} dB, {} list entries",
            out.stats.list_entries
        );
        assert!(db >= 45.0, "{label}: {db:.2} dB");
    }
    common::finish(ctx);
}

#[test]
fn occlusion_is_ordered_like_the_ground_truth() {
    let ctx = common::gpu();
    let mut eye = SyntheticEye::new(1.0, 4.0);
    eye.focus_d = [1.0; 3];
    let (objects, max_radius) = axis_for(&eye, 0.0, 3.0, 13);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let exact = ExactSynthetic {
        eye: eye.clone(),
        pupil_mm: 4.0,
        max_radius,
    };
    let (fg, bg) = ([0.9, 0.2, 0.1], [0.1, 0.3, 0.9]);
    // Sharp foreground (in focus, 1 D) left of x = 80 over a blurred background (3 D... far: 0 D).
    let sharp_over_blurred = Scene::new(160, 90, |x, _| {
        if x < 80 {
            (fg, 1.0)
        } else {
            (bg, f32::INFINITY)
        }
    });
    // Blurred foreground (3 D) over a sharp background (1 D).
    let blurred_over_sharp = Scene::new(
        160,
        90,
        |x, _| if x < 80 { (fg, 1.0 / 3.0) } else { (bg, 1.0) },
    );
    for (label, scene) in [
        ("sharp over blurred", &sharp_over_blurred),
        ("blurred over sharp", &blurred_over_sharp),
    ] {
        let out = splat(
            &ctx,
            &grid,
            SplatSettings {
                merge: NO_MERGE,
                ..SplatSettings::default()
            },
            scene,
            false,
        );
        let truth = reference::render(&scene.input(), &exact);
        let db = psnr(&out.color, &truth);
        eprintln!(
            "{label}: PSNR vs ground truth {db:.2} dB, max diff {:.2e}",
            max_rgb_difference(&out.color, &truth)
        );
        assert!(db >= 45.0, "{label}: {db:.2}");
        let row = |x: usize| out.color[45 * 160 + x];
        if label == "sharp over blurred" {
            // The in-focus foreground occludes everything behind it: its pixels stay exact.
            for x in 0..80 {
                assert!(
                    (0..3).all(|c| (row(x)[c] - fg[c]).abs() < 1e-5),
                    "x = {x}: {:?}",
                    row(x)
                );
            }
            // The blurred background does not spill over the sharp foreground but is itself
            // untouched far from the edge.
            assert!((0..3).all(|c| (row(159)[c] - bg[c]).abs() < 1e-4));
        } else {
            // The blurred foreground spills over the sharp background next to the edge.
            let spill = row(81);
            assert!(
                spill[0] > bg[0] + 0.05,
                "no foreground light beyond the edge: {spill:?}"
            );
            assert!((0..3).all(|c| (row(159)[c] - bg[c]).abs() < 1e-4));
        }
    }
    common::finish(ctx);
}

/// 96×64: large smooth regions that merge, a textured square and edges that do not.
fn merging_scene() -> Scene {
    Scene::new(96, 64, |x, y| {
        if (40..70).contains(&x) && (10..40).contains(&y) {
            (texture(x, y, 3.0), 0.4)
        } else if x < 30 {
            ([0.2, 0.4, 0.6], 0.5)
        } else {
            ([0.7, 0.7, 0.7], 2.0)
        }
    })
}

/// The colour rule's ε is a fraction of the white the image is shown at, not of 1: a frame in
/// cd/m² (a scene's white lies at hundreds of them) merges as the same frame in display units
/// does. Scaled by 1024 (a power of two, so every sum scales exactly) with the white scaled
/// alike, the merge decisions and the image are the same; the white left at 1 (the rule applied
/// in the frame's own units, as before) merges fewer blocks.
#[test]
fn the_colour_rule_is_relative_to_the_display_white() {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(0.2, 5.0);
    let (objects, max_radius) = axis_for(&eye, 0.0, 3.0, 13);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let scene = merging_scene();
    const SCALE: f32 = 1024.0;
    let bright = Scene {
        color: scene
            .color
            .iter()
            .map(|p| [p[0] * SCALE, p[1] * SCALE, p[2] * SCALE, p[3]])
            .collect(),
        depth: scene.depth.clone(),
        ..scene
    };
    let scene = merging_scene();
    let settings = |white: f32| SplatSettings {
        merge: MergeSettings {
            levels: 2,
            blur_per_block: 1.0,
            color_error: 1.0 / 255.0,
            white,
            ..MergeSettings::default()
        },
        ..SplatSettings::default()
    };
    let plain = splat(&ctx, &grid, settings(1.0), &scene, false);
    let scaled = splat(&ctx, &grid, settings(SCALE), &bright, false);
    let unscaled_rule = splat(&ctx, &grid, settings(1.0), &bright, false);
    let merged = |o: &SplatOutput| o.stats.live_fragments;
    assert!(
        merged(&plain) < 96 * 64,
        "the scene should merge some blocks ({} live fragments)",
        merged(&plain)
    );
    assert_eq!(
        merged(&scaled),
        merged(&plain),
        "same decisions, white scaled"
    );
    let worst = plain
        .color
        .iter()
        .zip(&scaled.color)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] * SCALE - b[c]).abs() / SCALE))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-6, "images differ by {worst} of white");
    assert!(
        merged(&unscaled_rule) > merged(&plain),
        "the negative control: ε taken in the frame's units merges fewer blocks ({} vs {})",
        merged(&unscaled_rule),
        merged(&plain)
    );
}

#[test]
fn every_pass_matches_its_cpu_step() {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(0.2, 5.0);
    let (objects, max_radius) = axis_for(&eye, 0.0, 3.0, 13);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let scene = merging_scene();
    // Blocks as wide as the blur (k = 1), so that this small blur makes 4×4 blocks.
    let merge = MergeSettings {
        levels: 2,
        blur_per_block: 1.0,
        color_error: 1.0 / 255.0,
        ..MergeSettings::default()
    };
    let settings = SplatSettings {
        merge,
        ..SplatSettings::default()
    };
    let out = splat(&ctx, &grid, settings, &scene, true);
    let gpu = out.intermediates.expect("kept");
    let frame = splat_cpu::Frame {
        width: 96,
        height: 64,
        tile: 8,
        dioptre_min: objects.min_d as f32,
        dioptre_step: objects.step_d as f32,
        max_radius,
        focal_px: (32.0 / 30f64.to_radians().tan()) as f32,
        group_tolerance_d: settings.blend.group_tolerance_d,
        block_reads: out.stats.layer_kernels,
    };
    let mut cpu = splat_cpu::fragments(&frame, &scene.color, &scene.depth, &grid.sets[0].radius_px);
    let core: Vec<f32> = grid.sets[0]
        .core_radii_px()
        .iter()
        .map(|c| c[0].min(c[1]).min(c[2]))
        .collect();
    let peak: Vec<f32> = grid.sets[0]
        .peak_radii_px()
        .iter()
        .map(|c| c[0].min(c[1]).min(c[2]))
        .collect();
    splat_cpu::merge_level(&frame, &mut cpu, &merge, &core, &peak, 2);
    splat_cpu::merge_level(&frame, &mut cpu, &merge, &core, &peak, 4);
    let merged = cpu.iter().filter(|f| f.size > 1).count();
    assert!(
        merged > 20,
        "the scene should exercise merging ({merged} merged fragments)"
    );
    assert!(cpu.iter().any(|f| f.size == 4), "no 4×4 merge happened");
    for (i, (g, c)) in gpu.fragments.iter().zip(&cpu).enumerate() {
        assert_eq!(
            g.size, c.size,
            "merge decision differs at fragment {i}: {g:?} vs {c:?}"
        );
        if c.size == 0 {
            continue;
        }
        assert_eq!(g.center, c.center, "fragment {i}");
        assert!(
            (g.depth - c.depth).abs() <= 1e-6 * c.depth,
            "fragment {i}: {g:?} vs {c:?}"
        );
        assert!(
            (g.dioptre - c.dioptre).abs() <= 1e-6 * c.dioptre.max(1.0),
            "fragment {i}"
        );
        for k in 0..3 {
            assert!(
                (g.radius[k] - c.radius[k]).abs() < 1e-4,
                "fragment {i}: {g:?} vs {c:?}"
            );
            assert!((g.color[k] - c.color[k]).abs() < 1e-6, "fragment {i}");
        }
        assert!((g.index - c.index).abs() < 1e-5, "fragment {i}");
    }
    // Use the GPU's fragments from here on, so float ties in radii cannot blur the comparison.
    let lists = splat_cpu::tile_lists(&frame, &gpu.fragments);
    let counts: Vec<u32> = lists.iter().map(|l| l.len() as u32).collect();
    assert_eq!(gpu.counts, counts, "tile counts");
    let mut running = 0u32;
    for (t, &count) in counts.iter().enumerate() {
        assert_eq!(gpu.offsets[t], running, "offset of tile {t}");
        running += count;
    }
    assert_eq!(gpu.offsets[counts.len()], running, "total");
    for (t, list) in lists.iter().enumerate() {
        let start = gpu.offsets[t] as usize;
        assert_eq!(
            &gpu.entries[start..start + list.len()],
            &list[..],
            "sorted list of tile {t}"
        );
    }
    assert_eq!(
        out.stats.live_fragments,
        gpu.fragments.iter().filter(|f| f.size > 0).count() as u64
    );
    // The cost counters: pairs within reach, and the reads the pixel walk makes for them.
    let (mut evaluations, mut reads) = (0u64, 0u64);
    for f in gpu.fragments.iter().filter(|f| f.size > 0) {
        let pairs = splat_cpu::reached_pixels(&frame, f).len() as u64;
        evaluations += pairs;
        reads += pairs * splat_cpu::reads_per_evaluation(&frame, f, out.stats.layer_kernels);
    }
    // Off the centre the footprint's edge falls between pixel centres at irrational offsets, so
    // a pixel within a rounding error of it may count on one side and not the other (the
    // kernel is zero there); the square around it, the old count, is a quarter larger.
    let near = |a: u64, b: u64| a.abs_diff(b) as f64 <= 1e-5 * b as f64 + 1.0;
    assert!(
        near(out.stats.kernel_evaluations, evaluations),
        "kernel evaluations: {} on the GPU, {evaluations} here",
        out.stats.kernel_evaluations
    );
    assert!(
        near(out.stats.texture_reads, reads),
        "texture reads: {} on the GPU, {reads} here",
        out.stats.texture_reads
    );
    assert!(
        reads > evaluations,
        "the scene should exercise reads beyond one per pair ({reads} for {evaluations})"
    );
    common::finish(ctx);
}

#[test]
fn huge_blur_long_lists_and_bands_render_the_same() {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(0.0, 9.0);
    let (objects, max_radius) = axis_for(&eye, 0.0, 3.5, 8);
    assert!(max_radius >= 30);
    let grid = eye.grid(objects, max_radius, &[4.0], 48);
    // Everything strongly blurred: every tile's list holds thousands of fragments, past the
    // shared-memory sort (2048), so the global-memory sort path runs too.
    let scene = Scene::new(64, 48, |x, y| {
        (texture(x, y, 0.7), if x < 32 { 0.3 } else { 0.35 })
    });
    let one = splat(
        &ctx,
        &grid,
        SplatSettings {
            merge: NO_MERGE,
            ..SplatSettings::default()
        },
        &scene,
        false,
    );
    assert_eq!(one.stats.bands, 1);
    assert!(
        one.stats.max_entries_per_tile > 2048,
        "{}",
        one.stats.max_entries_per_tile
    );
    let small = SplatSettings {
        merge: NO_MERGE,
        max_list_bytes: one.stats.list_entries * 8 / 3,
        ..SplatSettings::default()
    };
    let banded = splat(&ctx, &grid, small, &scene, false);
    assert!(banded.stats.bands >= 3, "{} bands", banded.stats.bands);
    assert_eq!(banded.color, one.color, "bands must not change the image");
    let truth = reference::render(
        &scene.input(),
        &ExactSynthetic {
            eye,
            pupil_mm: 4.0,
            max_radius,
        },
    );
    let db = psnr(&one.color, &truth);
    eprintln!(
        "huge blur: {} entries, max {} per tile, {} bands when limited; PSNR {db:.2} dB",
        one.stats.list_entries, one.stats.max_entries_per_tile, banded.stats.bands
    );
    assert!(db >= 45.0, "{db:.2}");
    common::finish(ctx);
}

#[test]
fn tile_sizes_agree_and_frames_are_deterministic() {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(0.4, 3.0);
    let (objects, max_radius) = axis_for(&eye, 0.0, 4.0, 17);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let scene = layered_scene();
    let base = splat(&ctx, &grid, SplatSettings::default(), &scene, false);
    let again = splat(&ctx, &grid, SplatSettings::default(), &scene, false);
    assert_eq!(base.color, again.color, "two runs differ");
    for tile_size in [16, 32] {
        let other = splat(
            &ctx,
            &grid,
            SplatSettings {
                tile_size,
                ..SplatSettings::default()
            },
            &scene,
            false,
        );
        let worst = max_rgb_difference(&other.color, &base.color);
        eprintln!("tile size {tile_size}: largest difference {worst:e}");
        assert_eq!(
            other.color, base.color,
            "tile size {tile_size} changes the image"
        );
    }
    let err = Splatter::new(
        &ctx,
        grid.clone(),
        SplatSettings {
            tile_size: 12,
            ..SplatSettings::default()
        },
    )
    .err()
    .unwrap();
    assert!(err.to_string().contains("tile size 12"), "{err}");
    common::finish(ctx);
}

/// A frame whose fragments exceed one storage-buffer binding is bound as four ranges of one
/// buffer (how a 3840×2160 frame fits lavapipe's 128 MiB bindings): every pass, merging
/// included, must read and write across the range boundaries exactly as through one binding.
#[test]
fn fragments_split_over_four_bindings_render_the_same() {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(0.2, 5.0);
    let (objects, max_radius) = axis_for(&eye, 0.0, 3.0, 13);
    let grid = eye.grid(objects, max_radius, &[4.0], 90);
    let scene = merging_scene();
    // Blocks as wide as the blur (k = 1), so that this small blur makes 4×4 blocks.
    let merge = MergeSettings {
        levels: 2,
        blur_per_block: 1.0,
        color_error: 1.0 / 255.0,
        ..MergeSettings::default()
    };
    let whole = SplatSettings {
        merge,
        ..SplatSettings::default()
    };
    let one = splat(&ctx, &grid, whole, &scene, true);
    let fragment_bytes = 48u64;
    let pixels = 96 * 64;
    // A third of the frame per binding: four ranges of 1536 fragments.
    let split = SplatSettings {
        max_fragment_binding_bytes: pixels * fragment_bytes / 3,
        ..whole
    };
    let four = splat(&ctx, &grid, split, &scene, true);
    let (a, b) = (one.intermediates.unwrap(), four.intermediates.unwrap());
    assert_eq!(a.fragments.len(), b.fragments.len());
    for (i, (x, y)) in a.fragments.iter().zip(&b.fragments).enumerate() {
        assert_eq!(
            bytemuck::bytes_of(x),
            bytemuck::bytes_of(y),
            "fragment {i} differs when split"
        );
    }
    assert_eq!(one.color, four.color, "the split must not change the image");
    assert!(one.stats.live_fragments < pixels, "merging ran");
    // Past four ranges the frame is refused with the device's limit in the message.
    let too_small = SplatSettings {
        max_fragment_binding_bytes: pixels * fragment_bytes / 5,
        ..whole
    };
    let err = Splatter::new(&ctx, grid.clone(), too_small)
        .unwrap()
        .render(
            &scene.input(),
            ViewState {
                pupil_mm: 4.0,
                focus_d: grid.focus_d[0],
            },
            false,
        )
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("storage-buffer bindings"), "{err}");
    common::finish(ctx);
}
