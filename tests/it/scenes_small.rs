//! Every shipped scene renders and exports at small sizes as well as at 1280×720 (issue 29,
//! case 5: `video --scene walk --size 64x36` once stopped on a 1.9 mm depth, 529 D, from a
//! column facet seen edge-on).
//!
//! The raster level is checked at all three sizes over the animation: every depth lies in the
//! camera's clip range, and the nearest vergence of a small frame is no nearer than the
//! 1280×720 frame's (a coarser sampling of the same surfaces can miss a near point, never
//! invent one). The CLI level renders and exports each scene at 64×36 and 160×90.

use crate::common;
use crate::common::{ocular, temp_dir};
use std::path::Path;

use ocular::psf::{plan_for_scene, GridAxes, Screen};
use ocular::render::{dioptre_range, scene_needs, EyeState, Rasterizer};
use ocular::scene::Scene;

const SIZES: [(u32, u32); 3] = [(64, 36), (160, 90), (1280, 720)];
/// Instants per animated scene (the video planner looks at 48 over the whole animation).
const TIMES: usize = 16;

fn times(scene: &Scene) -> Vec<f64> {
    let d = scene.duration_s();
    if d <= 0.0 {
        return vec![0.0];
    }
    (0..TIMES)
        .map(|k| d * k as f64 / (TIMES - 1) as f64)
        .collect()
}

#[test]
fn shipped_scenes_have_physical_depth_and_a_kernel_plan_at_every_size() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    for name in Scene::builtin_names() {
        let scene = Scene::load(name).unwrap();
        // nearest vergence per instant and size
        let mut nearest_d = vec![[0.0f64; 3]; times(&scene).len()];
        for (s, &(w, h)) in SIZES.iter().enumerate() {
            let mut ranges = Vec::new();
            for (i, &t) in times(&scene).iter().enumerate() {
                let state = scene.at_time(t);
                let (near, far) = (state.camera.near_m, state.camera.far_m);
                let frame = raster.render(&ctx, &state, w, h).unwrap();
                for (p, &d) in frame.depth_m.iter().enumerate() {
                    let d = f64::from(d);
                    assert!(
                        d >= near * (1.0 - 1e-5) && d <= far * (1.0 + 1e-5),
                        "{name} {w}x{h} t = {t:.3} s: depth {d} m at pixel ({}, {}) outside the \
                         clip range {near}..{far} m",
                        p as u32 % w,
                        p as u32 / w
                    );
                }
                let range = dioptre_range(&frame.depth_m, w, h, state.camera.fov_y_deg);
                nearest_d[i][s] = range.1;
                ranges.push(range);
            }
            let states = [EyeState {
                focus_d: 1.0,
                pupil_mm: 4.0,
            }];
            let screen = Screen {
                fov_y_deg: scene.at_time(0.0).camera.fov_y_deg,
                height_px: h,
            };
            let needs = scene_needs(&ranges, &states, screen);
            let plan = plan_for_scene(&needs, &GridAxes::default());
            assert!(plan.is_ok(), "{name} {w}x{h}: {}", plan.unwrap_err());
            eprintln!(
                "{name} {w}x{h}: scene {:.3}..{:.3} D over {} instant(s)",
                needs.dioptre_min,
                needs.dioptre_max,
                ranges.len()
            );
        }
        for (i, n) in nearest_d.iter().enumerate() {
            for s in 0..2 {
                assert!(
                    n[s] <= n[2] * 1.05 + 0.05,
                    "{name} instant {i}: nearest {:.3} D at {}x{} but {:.3} D at 1280x720",
                    n[s],
                    SIZES[s].0,
                    SIZES[s].1,
                    n[2]
                );
            }
        }
    }
    drop(raster);
    common::finish(ctx);
}

/// `ocular COMMAND` of `scene` at `size` through the myopic eye into `out`, with `extra` and
/// the kernel cache `cache`, which must succeed.
fn run(command: &str, (scene, size): (&str, &str), out: &Path, extra: &[&str], cache: &Path) {
    let mut cmd = ocular();
    cmd.args([command, "--scene", scene, "--eye", "myopia", "--size", size])
        .arg("-o")
        .arg(out)
        .args(extra)
        .arg("--cache")
        .arg(cache);
    let output = cmd.output().unwrap();
    assert!(
        output.status.success(),
        "{cmd:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

#[test]
fn shipped_scenes_render_and_export_at_64x36_and_160x90() {
    let dir = temp_dir("cli");
    let cache = dir.join("cache");
    for name in Scene::builtin_names() {
        let animated = Scene::load(name).unwrap().duration_s() > 0.0;
        for size in ["64x36", "160x90"] {
            let png = dir.join(format!("{name}-{size}.png"));
            run("render", (name, size), &png, &[], &cache);
            assert!(png.is_file(), "{}", png.display());
            let frames = dir.join(format!("{name}-{size}"));
            // a still scene exports a focus sweep; the walk its own animation
            let extra: &[&str] = if animated {
                &["--frames", "0..3"]
            } else {
                &[
                    "--focus-sweep",
                    "0.25..6",
                    "--duration",
                    "0.1",
                    "--fps",
                    "30",
                ]
            };
            run("video", (name, size), &frames, extra, &cache);
            let written = std::fs::read_dir(&frames)
                .unwrap()
                .filter(|e| {
                    e.as_ref()
                        .unwrap()
                        .path()
                        .extension()
                        .is_some_and(|x| x == "png" || x == "exr")
                })
                .count();
            assert_eq!(
                written,
                3,
                "{name} {size}: {written} frames in {}",
                frames.display()
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
