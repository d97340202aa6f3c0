//! Wide frames: vergence along each pixel's ray (a flat wall is farther at the corners) and
//! kernels laid out with the pinhole's local scale (equal angular blur grows by 1/cos²θ
//! radially and 1/cos θ tangentially on the screen). Expected values are written here from the
//! geometry; the seed paper's geometry (view-axis vergence, the centre's scale) is the negative
//! control.

use crate::common;

use common::synthetic::{ExactSynthetic, SyntheticEye};
use ocular::psf::DioptreAxis;
use ocular::render::splat::{FrameInput, MergeSettings, SplatSettings, Splatter, ViewState};
use ocular::render::{dioptre_range, reference, BlendSettings};

fn settings(blend: BlendSettings) -> SplatSettings {
    SplatSettings {
        merge: MergeSettings {
            levels: 0,
            ..MergeSettings::default()
        },
        blend,
        ..SplatSettings::default()
    }
}

/// A wall facing the camera at 5 m, 16:9, 50° vertical field: 0.200 D at the centre and
/// 1/(5·√(1 + tan²25°·(1 + (16/9)²))) = 0.145 D in the corners, in the fragments the splat
/// makes and in the planned dioptre range.
#[test]
fn a_flat_wall_has_the_vergence_of_its_ray_length() {
    let (w, h, fov) = (96u32, 54u32, 50.0f64);
    let color = vec![[0.5f32, 0.5, 0.5, 1.0]; (w * h) as usize];
    let depth = vec![5.0f32; (w * h) as usize];
    let input = FrameInput {
        width: w,
        height: h,
        color: &color,
        depth_m: &depth,
        fov_y_deg: fov,
        hidden_layers: &[],
        mixed: None,
    };
    let (lo, hi) = dioptre_range(&depth, w, h, fov);
    let tan_half = (0.5 * fov).to_radians().tan();
    let corner = |x: f64, y: f64| {
        // Direction of a pixel centre: (tan of its horizontal and vertical angles).
        let tx = (x + 0.5 - 0.5 * f64::from(w)) / (0.5 * f64::from(h)) * tan_half;
        let ty = (y + 0.5 - 0.5 * f64::from(h)) / (0.5 * f64::from(h)) * tan_half;
        1.0 / (5.0 * (1.0 + tx * tx + ty * ty).sqrt())
    };
    eprintln!(
        "planned range {lo:.4}..{hi:.4} D; corner {:.4} D",
        corner(0.0, 0.0)
    );
    assert!((lo - corner(0.0, 0.0)).abs() < 1e-6, "{lo}");
    assert!((0.1445..0.1465).contains(&lo));
    assert!((hi - 0.2).abs() < 1e-3, "{hi}");

    let eye = SyntheticEye::new(0.0, 3.0);
    let grid = eye.grid(DioptreAxis::spanning(0.0, 1.0, 5), 3, &[4.0], h);
    let ctx = common::gpu();
    for (blend, wide) in [
        (BlendSettings::default(), true),
        (BlendSettings::paper(), false),
    ] {
        let mut splatter = Splatter::new(&ctx, grid.clone(), settings(blend)).unwrap();
        let out = splatter
            .render(
                &input,
                ViewState {
                    pupil_mm: 4.0,
                    focus_d: 0.0,
                },
                true,
            )
            .unwrap();
        let fragments = out.intermediates.unwrap().fragments;
        let worst = fragments
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let want = corner(f64::from(i as u32 % w), f64::from(i as u32 / w));
                (f64::from(f.dioptre) - want).abs()
            })
            .fold(0.0, f64::max);
        eprintln!("wide-field geometry {wide}: worst fragment vergence error {worst:.2e} D");
        if wide {
            assert!(worst < 1e-6, "{worst}");
        } else {
            assert!(
                worst > 0.05,
                "negative control: view-axis vergence passed ({worst})"
            );
        }
    }
    common::finish(ctx);
}

/// Point lights 0.25 m from the eye along their rays at 0°, 25°, 35° and 42° across a 60°-high
/// 641×361 frame: the spots' widths grow by 1/cos²θ horizontally (radially) and 1/cos θ
/// vertically (tangentially), within 5 %, in the splat and in the reference.
#[test]
fn equal_angular_blur_grows_with_the_pinhole_scale() {
    let (w, h, fov) = (641usize, 361usize, 60.0f64);
    let focal = 0.5 * h as f64 / (0.5 * fov).to_radians().tan();
    let cy = 180usize; // pixel row whose centre is on the horizontal axis
                       // 35° on the left, so that no spot's measuring window reaches another spot.
    let angles = [0.0f64, 25.0, -35.0, 42.0];
    let columns: Vec<usize> = angles
        .iter()
        .map(|a: &f64| (320.0 + focal * a.to_radians().tan()).round() as usize)
        .collect();
    // Around each light a black patch of the sphere 0.25 m from the eye (the lights' own
    // distance), large enough for the stretched kernel, so that every spot is its kernel,
    // unaffected by what single-layer input hides behind a point; elsewhere black at infinity.
    let mut color = vec![[0.0f32, 0.0, 0.0, 1.0]; w * h];
    let near = |x: usize, y: usize| {
        columns
            .iter()
            .any(|&c| x.abs_diff(c) <= 32 && y.abs_diff(cy) <= 32)
    };
    let mut depth: Vec<f32> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let u = x as f64 + 0.5 - 0.5 * w as f64;
            let v = y as f64 + 0.5 - 0.5 * h as f64;
            if near(x, y) {
                (0.25 * focal / (focal * focal + u * u + v * v).sqrt()) as f32
            } else {
                f32::INFINITY
            }
        })
        .collect();
    for &x in &columns {
        let u = x as f64 + 0.5 - 0.5 * w as f64;
        let cos = focal / focal.hypot(u);
        color[cy * w + x] = [1.0; 4];
        depth[cy * w + x] = (0.25 * cos) as f32; // view-axis depth of 0.25 m along the ray
    }
    let input = FrameInput {
        width: w as u32,
        height: h as u32,
        color: &color,
        depth_m: &depth,
        fov_y_deg: fov,
        hidden_layers: &[],
        mixed: None,
    };
    let eye = SyntheticEye::new(0.0, 3.0); // about 12 px of blur at 4 D
    let objects = DioptreAxis::spanning(0.0, 6.0, 13);
    let grid = eye.grid(objects, 18, &[4.0], h as u32);
    let exact = ExactSynthetic {
        eye,
        pupil_mm: 4.0,
        max_radius: 18,
    };
    // RMS width (px) of the green spot around column x, horizontally and vertically.
    let widths = |image: &[[f32; 4]], x: usize| common::spots::rms_widths(image, w, (x, cy), 45);
    let ctx = common::gpu();
    let mut control_worst = 0.0f64;
    let mut worst = 0.0f64;
    for (blend, name) in [
        (BlendSettings::default(), "splat"),
        (BlendSettings::paper(), "splat, the paper's geometry"),
    ] {
        let mut splatter = Splatter::new(&ctx, grid.clone(), settings(blend)).unwrap();
        let view = ViewState {
            pupil_mm: 4.0,
            focus_d: 0.0,
        };
        let image = splatter.render(&input, view, false).unwrap().color;
        let images = if blend.wide_field {
            vec![
                (image, name),
                (reference::render(&input, &exact), "reference"),
            ]
        } else {
            vec![(image, name)]
        };
        for (image, name) in images {
            let (w0, h0) = widths(&image, columns[0]);
            eprintln!("{name}: centre spot {w0:.3} × {h0:.3} px");
            for (k, &x) in columns.iter().enumerate().skip(1) {
                let u = x as f64 + 0.5 - 0.5 * w as f64;
                let cos = focal / focal.hypot(u);
                let (wx, wy) = widths(&image, x);
                let (gx, gy) = (wx / w0, wy / h0);
                let (ex, ey) = (1.0 / (cos * cos), 1.0 / cos);
                eprintln!(
                    "{name}, {:>2}°: growth {gx:.3} × {gy:.3} (pinhole {ex:.3} × {ey:.3})",
                    angles[k].abs()
                );
                let err = ((gx / ex - 1.0).abs()).max((gy / ey - 1.0).abs());
                if blend.wide_field {
                    worst = worst.max(err);
                } else {
                    control_worst = control_worst.max(err);
                }
            }
        }
    }
    assert!(worst < 0.05, "growth off the pinhole scale by {worst}");
    assert!(
        control_worst > 0.05,
        "negative control: the paper's geometry passed ({control_worst})"
    );
    common::finish(ctx);
}

/// Merging off the frame's centre, in a common case: colonnade's blurred lamps, 14–27° above
/// the axis, through the astigmatic eye at 640×360 (kernels of 5–8 px, so blocks merge). Off
/// the centre a block's pixels lie cos²θ·δ apart in kernel space. With the layer kernels (the
/// default) a merged block reads its pixels where they lie: a 2×2 block its four pixels'
/// kernels, a larger one its box in the summed-area table. With the radius levels its one read
/// assumes δ, a true PSF varies texel to texel, and `--merge-scale-error` bounds the misread.
/// Each merged frame is judged against the same path with merging off: the reference shares
/// kernels and blend, so it judges merging alone. Negative control: the levels' bound lifted
/// (the rule before the bound). Measured (docs/validation.md, "Merging in the wide field"):
/// layer kernels 92.30 dB, levels with the bound 93.54 dB, levels with it lifted 69.97 dB.
const MERGED_BAR_DB: f64 = 90.0;

#[test]
fn merging_off_the_centre_keeps_the_unmerged_image() {
    use common::{module_cache, ocular, ok, p, temp_dir};
    let dir = temp_dir("merge-wide");
    let cache = module_cache();
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(format!("{name}.exr"));
        let run = ocular()
            .args(["render", "--scene", "colonnade", "--eye", "astigmatism"])
            .args(["--size", "640x360", "--focus-d", "0.5", "--pupil-mm", "5"])
            .args(["--cache", p(&cache), "-o", p(&out)])
            .args(extra)
            .output()
            .unwrap();
        ok(&run);
        ocular::image_io::read_exr_rgba(&out).unwrap().pixels
    };
    // PSNR at the unmerged frame's brightest channel value (the lamps, about 5000 times the
    // walls): what the merge misplaces is the lamps' light.
    let against = |unmerged: Vec<[f32; 4]>, merged: Vec<[f32; 4]>| {
        let peak = unmerged
            .iter()
            .flat_map(|q| &q[..3])
            .fold(0.0f32, |m, &v| m.max(v));
        let scaled = |image: Vec<[f32; 4]>| -> Vec<[f32; 4]> {
            image.iter().map(|q| q.map(|v| v / peak)).collect()
        };
        common::pixels::psnr(&scaled(unmerged), &scaled(merged))
    };
    let layered = against(
        render("unmerged", &["--merge-levels", "0"]),
        render("merged", &[]),
    );
    let levels = ["--level-kernels"];
    let levels_unmerged = render(
        "levels-unmerged",
        &["--level-kernels", "--merge-levels", "0"],
    );
    let bounded = against(levels_unmerged.clone(), render("levels", &levels));
    let unbounded = against(
        levels_unmerged,
        render(
            "unbounded",
            &["--level-kernels", "--merge-scale-error", "1000"],
        ),
    );
    eprintln!(
        "layer kernels {layered:.2} dB; radius levels {bounded:.2} dB, bound lifted {unbounded:.2} dB"
    );
    assert!(layered >= MERGED_BAR_DB, "layer kernels: {layered:.2} dB");
    assert!(bounded >= MERGED_BAR_DB, "radius levels: {bounded:.2} dB");
    assert!(
        unbounded < MERGED_BAR_DB,
        "negative control passed: {unbounded:.2} dB"
    );
}
