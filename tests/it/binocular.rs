//! Two eyes: the pinhole geometry of converging eyes (disparity of midline points, the fixated
//! point centred), judged on rasterised frames against the exact form written here; and the
//! CLI's binocular render (yoked accommodation of a monovision pair, outputs, bad options).

use ocular::render::binocular::{eye_cameras, eye_positions, point_ahead, DEFAULT_IPD_MM};
use ocular::render::Rasterizer;
use ocular::scene::Scene;

use crate::common::{blender, finish, gpu, module_cache, ocular_run, temp_dir};

const SIZE: (u32, u32) = (640, 360);
const FOV_Y_DEG: f64 = 20.0;

/// A scene of one white sphere `d_m` ahead and `x_m` right of the view, lit evenly, on near
/// black; its radius spans about 8 pixels at any distance.
fn marker_scene(x_m: f64, d_m: f64) -> Scene {
    let focal = 0.5 * f64::from(SIZE.1) / (FOV_Y_DEG.to_radians() * 0.5).tan();
    sphere_scene([x_m, 0.0, -d_m], d_m * 8.0 / focal, "")
}

/// One white sphere of `radius_m` at `centre_m` (view along −z), lit evenly, on near black,
/// seen through a FOV_Y_DEG camera at SIZE; `extra` is appended to the scene's TOML.
fn sphere_scene(centre_m: [f64; 3], radius_m: f64, extra: &str) -> Scene {
    let [x, y, z] = centre_m;
    let text = format!(
        r#"
name = "marker"
[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
fov_y_deg = {FOV_Y_DEG}
near_m = 0.05
far_m = 500.0
resolution = [{w}, {h}]
[background]
color = [1.0, 1.0, 1.0]
luminance_cd_m2 = 0.01
[[light]]
kind = "ambient"
illuminance_lux = 300.0
[[object]]
kind = "sphere"
radius_m = {radius_m}
segments = 256
translate = [{x}, {y}, {z}]
color = [0.8, 0.8, 0.8]
{extra}"#,
        w = SIZE.0,
        h = SIZE.1,
    );
    Scene::from_toml(&text, "marker scene", std::path::Path::new(".")).unwrap()
}

/// An eye file estimated from the prescription `rx` (4 mm pupil) by the CLI, in `dir`.
fn estimated_eye(dir: &std::path::Path, rx: &str) -> std::path::PathBuf {
    let file = dir.join(format!("eye{rx}.toml"));
    let out = ocular_run(&[
        "eye",
        "estimate",
        "--rx",
        rx,
        "--pupil-mm",
        "4",
        "-o",
        file.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    file
}

/// The centroid of a frame's light above its background, in pixel coordinates (a pixel's
/// centre at i + 0.5).
fn centroid(color: &[[f32; 4]], width: u32) -> (f64, f64) {
    let value = |p: &[f32; 4]| f64::from(p[0] + p[1] + p[2]);
    let background = color.iter().map(value).fold(f64::INFINITY, f64::min);
    let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
    for (i, p) in color.iter().enumerate() {
        let v = value(p) - background;
        let (x, y) = (
            (i as u32 % width) as f64 + 0.5,
            (i as u32 / width) as f64 + 0.5,
        );
        sx += v * x;
        sy += v * y;
        s += v;
    }
    assert!(s > 0.0, "the marker is not in the frame");
    (sx / s, sy / s)
}

#[test]
fn midline_points_land_at_the_disparity_of_converging_eyes() {
    let ctx = gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let fixation_m = 2.0;
    let b = 0.5 * DEFAULT_IPD_MM * 1e-3;
    let focal = 0.5 * f64::from(SIZE.1) / (FOV_Y_DEG.to_radians() * 0.5).tan();
    let (cx, cy) = (0.5 * f64::from(SIZE.0), 0.5 * f64::from(SIZE.1));
    for d in [0.5, 1.0, fixation_m, 4.0] {
        let scene = marker_scene(0.0, d);
        let mut state = scene.at_time(0.0);
        let camera = state.camera;
        let positions = eye_positions(&camera, 2.0 * b);
        assert_eq!(positions[0][0], -b);
        let cameras = eye_cameras(&camera, 2.0 * b, point_ahead(&camera, fixation_m));
        let mut xs = [0.0; 2];
        for (e, eye_camera) in cameras.iter().enumerate() {
            state.camera = *eye_camera;
            let frame = raster.render(&ctx, &state, SIZE.0, SIZE.1).unwrap();
            let (x, y) = centroid(&frame.color, SIZE.0);
            // Exact: an eye at x = ∓b turned by atan(b/D) towards the midline sees the point
            // at angle atan(b/d) − atan(b/D) from its axis, on the side away from itself.
            let angle = (b / d).atan() - (b / fixation_m).atan();
            let sign = if e == 0 { 1.0 } else { -1.0 };
            let expected = cx + sign * focal * angle.tan();
            assert!(
                (x - expected).abs() <= 0.1 && (y - cy).abs() <= 0.1,
                "d = {d} m, eye {e}: at ({x:.3}, {y:.3}), expected ({expected:.3}, {cy:.3})"
            );
            xs[e] = x;
        }
        let disparity = xs[0] - xs[1];
        let exact = 2.0 * focal * ((b / d).atan() - (b / fixation_m).atan()).tan();
        let small_angle = 2.0 * b * focal * (1.0 / d - 1.0 / fixation_m);
        assert!(
            (disparity - exact).abs() <= 0.1,
            "d = {d} m: disparity {disparity:.3} px, exact {exact:.3} px (small-angle {small_angle:.3})"
        );
        if d == fixation_m {
            assert!(
                disparity.abs() <= 0.1,
                "the fixated point is not centred: {disparity}"
            );
        }
    }
    // A control: parallel eyes (fixation at infinity) do not centre the point at 2 m.
    let scene = marker_scene(0.0, fixation_m);
    let mut state = scene.at_time(0.0);
    let parallel = eye_cameras(&state.camera, 2.0 * b, None);
    state.camera = parallel[0];
    let frame = raster.render(&ctx, &state, SIZE.0, SIZE.1).unwrap();
    let (x, _) = centroid(&frame.color, SIZE.0);
    assert!(
        (x - cx).abs() > 5.0,
        "parallel eyes centred the point at {x}"
    );
    drop(raster);
    finish(ctx);
}

fn json(args: &[&str]) -> serde_json::Value {
    let out = ocular_run(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn a_monovision_pair_shares_one_accommodation() {
    let dir = temp_dir("monovision");
    let cache = module_cache();
    let cache = cache.to_str().unwrap();
    // The left eye emmetropic, the right myopic by 1.5 D: the same eye behind a +1.5 D contact
    // lens would be the textbook fit; here two eyes estimated from prescriptions.
    let near_eye = estimated_eye(&dir, "-1.5");
    let output = dir.join("view.png");
    let run = |focus_m: &str| {
        json(&[
            "render",
            "--scene",
            "chart",
            "--size",
            "64x36",
            "--eye",
            "healthy",
            "--eye-right",
            near_eye.to_str().unwrap(),
            "--age",
            "55",
            "--pupil-mm",
            "3",
            "--focus-m",
            focus_m,
            "--quality",
            "fast",
            "--cache",
            cache,
            "-o",
            output.to_str().unwrap(),
            "--json",
        ])
    };
    let far = run("6");
    let near = run("0.4");
    let eyes = |v: &serde_json::Value| {
        let e = v["eyes"].as_array().unwrap();
        [0, 1].map(|k| {
            (
                e[k]["far_point_d"].as_f64().unwrap(),
                e[k]["residual_defocus_d"].as_f64().unwrap(),
            )
        })
    };
    let [(fp_l, far_l), (fp_r, far_r)] = eyes(&far);
    assert!(
        fp_r - fp_l > 1.2,
        "far points {fp_l} and {fp_r}: the right eye should be myopic"
    );
    // Far: the left eye drives and sees the far chart sharp (within the healthy eye's own
    // slight myopia: its far point is about 0.2 D); the right keeps its myopia.
    assert_eq!(far["driver"], "left", "{far}");
    assert!(
        far_l.abs() < 0.1 && far_r < -1.2,
        "residuals {far_l}, {far_r}"
    );
    // Near, at 55 (Hofstetter: 2 D of accommodation, short of the 2.5 D the left eye needs):
    // the right eye drives, the left blurs.
    let [(_, near_l), (_, near_r)] = eyes(&near);
    assert_eq!(near["driver"], "right", "{near}");
    assert!(
        near_r.abs() < 0.02 && near_l > 1.0,
        "residuals {near_l}, {near_r}"
    );
    for side in ["left", "right"] {
        assert!(dir.join(format!("view-{side}.png")).exists());
    }
}

#[test]
fn binocular_options_are_checked() {
    let cases: [(&[&str], &str); 9] = [
        (&["render", "--ipd-mm", "63"], "--binocular"),
        (&["bench", "--ipd-mm", "63"], "--binocular"),
        (&["bench", "--eye-right", "healthy"], "--binocular"),
        (&["bench", "--binocular", "--ipd-mm", "90"], "--ipd-mm"),
        (&["render", "--binocular", "--ipd-mm", "20"], "--ipd-mm"),
        (
            &[
                "render",
                "--color",
                "x.exr",
                "--color-right",
                "y.exr",
                "--fov-y",
                "40",
            ],
            "--binocular",
        ),
        (
            &[
                "render",
                "--binocular",
                "--color",
                "x.exr",
                "--fov-y",
                "40",
                "--ipd-mm",
                "60",
            ],
            "--ipd-mm",
        ),
        (
            &["render", "--binocular", "--color", "x.exr", "--fov-y", "40"],
            "x.exr",
        ),
        (
            &["render", "--binocular", "--method", "reference"],
            "--method splat",
        ),
    ];
    for (args, expected) in cases {
        let out = ocular_run(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(expected) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
}

/// An E on its card `d_m` ahead on the midline, before a wall, in a narrow field so that a
/// dioptre of defocus spans pixels.
fn letter_scene(d_m: f64) -> std::sync::Arc<Scene> {
    let text = format!(
        r#"
name = "letter"
[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
fov_y_deg = 10.0
near_m = 0.05
far_m = 50.0
resolution = [192, 108]
[background]
color = [0.8, 0.8, 0.8]
luminance_cd_m2 = 40.0
[[light]]
kind = "ambient"
illuminance_lux = 400.0
[[object]]
kind = "optotype"
letter = "E"
direction = "right"
logmar = 1.3
translate = [0.0, 0.0, {z}]
[[object]]
kind = "plane"
size_m = [20.0, 12.0]
translate = [0.0, 0.0, -10.0]
color = [0.35, 0.33, 0.3]
"#,
        z = -d_m
    );
    std::sync::Arc::new(Scene::from_toml(&text, "letter", std::path::Path::new(".")).unwrap())
}

/// PSNR (dB, peak 1 after the exposure) of `a` against `b` over columns [x0, x1) of a
/// 192-wide frame, the middle third of its rows (where the letter is).
fn region_psnr(a: &[[f32; 4]], b: &[[f32; 4]], (x0, x1): (usize, usize), scale: f32) -> f64 {
    let (w, h) = (192usize, 108usize);
    let (mut se, mut n) = (0.0f64, 0usize);
    for y in h / 3..2 * h / 3 {
        for x in x0..x1 {
            let (p, q) = (a[y * w + x], b[y * w + x]);
            for c in 0..3 {
                let d = f64::from(((p[c] - q[c]) * scale).clamp(-1.0, 1.0));
                se += d * d;
                n += 1;
            }
        }
    }
    10.0 * (n as f64 / se.max(1e-20)).log10()
}

#[test]
fn monovision_frames_are_sharp_where_each_eye_drives_and_independent_eyes_would_differ() {
    use ocular::render::binocular::{render_pair, PairRequest};
    use ocular::render::frame_plan::FocusAsked;
    use ocular::render::live::{LiveOptions, LiveRenderer, SceneArg};

    let dir = temp_dir("monovision-frames");
    let near_file = estimated_eye(&dir, "-1.5");
    let near_eye = ocular::eye::load(&near_file).unwrap().eye;
    let far_eye = ocular::eye::Eye::preset("healthy").unwrap();
    let live = LiveRenderer::new(gpu(), Some(module_cache()), 4);
    let mut raster = Rasterizer::new(live.context()).unwrap();
    let options = |focus_m: f64| LiveOptions {
        focus: Some(FocusAsked::DistanceM(focus_m)),
        pupil_mm: Some(5.0),
        age: 55.0,
        ..LiveOptions::default()
    };
    // The fixated letter is centred in both eyes' frames: its card spans these columns.
    let letter = (72, 120);
    for (focus_m, sharp_eye) in [(6.0, 0), (0.4, 1)] {
        let scene = letter_scene(focus_m);
        let pair = render_pair(
            &live,
            &PairRequest {
                scene: &scene,
                eyes: [&far_eye, &near_eye],
                options: options(focus_m),
                corrections: Default::default(),
                size: (192, 108),
                time_s: 0.0,
                ipd_m: 0.063,
            },
        )
        .unwrap();
        assert_eq!(pair.yoke.driver, sharp_eye, "at {focus_m} m");
        let scale = 2f32.powf(pair.exposure_ev);
        // Each eye against the sharp frame from its own position: the driving eye's letter is
        // near it, the other's is not.
        let quality = [0, 1].map(|e| {
            let mut state = scene.at_time(0.0);
            state.camera = pair.geometry.unwrap().cameras[e];
            let sharp = raster.render(live.context(), &state, 192, 108).unwrap();
            region_psnr(&pair.frames[e].color, &sharp.color, letter, scale)
        });
        let other = 1 - sharp_eye;
        assert!(
            quality[sharp_eye] > quality[other] + 6.0,
            "at {focus_m} m the {} eye should see the letter sharper: {quality:?} dB",
            ["left", "right"][sharp_eye]
        );
        // The other eye's frame is the single-eye render of its yoked state …
        let single = |focus_d: f64| {
            let o = LiveOptions {
                focus: Some(FocusAsked::Dioptres(focus_d)),
                exposure_ev: Some(f64::from(pair.exposure_ev)),
                ..options(focus_m)
            };
            let eye = [&far_eye, &near_eye][other];
            let (f, _) = live
                .render_scene_from(
                    SceneArg::Loaded(&scene),
                    eye,
                    &o,
                    Some((192, 108)),
                    0.0,
                    Some(pair.geometry.unwrap().cameras[other]),
                )
                .unwrap();
            f.color
        };
        let yoked = single(pair.yoke.focus_d[other]);
        let same = region_psnr(&pair.frames[other].color, &yoked, (0, 192), scale);
        assert!(
            same > 60.0,
            "the pair's frame is not its eye state's: {same:.1} dB"
        );
        // … and, near, not what that eye would see accommodating alone (the negative control:
        // the left eye alone would spend its 2 D on the card). Far, both models agree: the
        // myopic eye is relaxed either way.
        let demand = pair.demand_d[other];
        let amplitude = pair.amplitude_d[other].unwrap_or(f64::INFINITY);
        let alone_d = demand.clamp(pair.far_point_d[other], pair.far_point_d[other] + amplitude);
        let alone = single(alone_d);
        let differs = region_psnr(&pair.frames[other].color, &alone, letter, scale);
        if sharp_eye == 1 {
            assert!(
                (alone_d - pair.yoke.focus_d[other]).abs() > 0.5 && differs < 30.0,
                "accommodating alone ({alone_d:.2} D vs {:.2} D) looks the same: {differs:.1} dB",
                pair.yoke.focus_d[other]
            );
            eprintln!(
                "near: left eye yoked {:.2} D vs alone {alone_d:.2} D: {differs:.1} dB apart; \
                 letter vs sharp {quality:?} dB",
                pair.yoke.focus_d[other]
            );
        } else {
            assert!((alone_d - pair.yoke.focus_d[other]).abs() < 1e-9);
            eprintln!("far: letter vs sharp {quality:?} dB");
        }
    }
    drop(raster);
    finish(live.into_context());
}

/// The entrance pupil's depth behind the corneal vertex (mm): the stop at the lens's anterior
/// vertex imaged backwards through the two corneal surfaces by paraxial vergences, with
/// Navarro's indices (cornea 1.376, aqueous 1.3374). Navarro's eye gives 3.04 mm.
fn entrance_pupil_depth_mm(eye: &ocular::eye::Eye) -> f64 {
    let (n_cornea, n_aqueous) = (1.376, 1.3374);
    let c = &eye.cornea;
    // reversed: light leaves the stop towards the cornea; radii change sign
    let mut vergence = n_aqueous / -eye.aqueous_depth_mm;
    vergence += (n_cornea - n_aqueous) / -c.posterior.radius_mm[0];
    vergence /= 1.0 - c.thickness_mm / n_cornea * vergence;
    vergence += (1.0 - n_cornea) / -c.anterior.radius_mm[0];
    -1.0 / vergence
}

#[test]
fn glasses_of_different_powers_give_each_eye_its_image_size() {
    use ocular::render::binocular::{render_pair, PairRequest};
    use ocular::render::frame_plan::Correction;
    use ocular::render::live::{LiveOptions, LiveRenderer};

    // A bright sphere far away, 5° right of the view: its image lies at f·M·tan θ from the
    // centre of each (parallel) eye's frame, M the eye's spectacle magnification.
    let (distance_m, angle_deg): (f64, f64) = (100.0, 5.0);
    let x_m = distance_m * angle_deg.to_radians().tan();
    let focal = 0.5 * f64::from(SIZE.1) / (FOV_Y_DEG.to_radians() * 0.5).tan();
    let scene = std::sync::Arc::new(marker_scene(x_m, distance_m));
    // An anisometropic pair: a mild and a strong myope, each in glasses of its own power; eyes
    // estimated from the prescriptions alone have no coma to shift an image's centroid.
    let powers_d = [-0.25, -6.0];
    let dir = temp_dir("aniseikonia");
    let eyes = powers_d.map(|p| {
        ocular::eye::load(&estimated_eye(&dir, &format!("{p}")))
            .unwrap()
            .eye
    });
    let vertex_mm = 12.0;
    let corrections = powers_d.map(|p| Correction {
        spectacle: Some(ocular::eye::Spectacle::new(p, 0.0, 180.0, vertex_mm).unwrap()),
        vertex_mm: Some(vertex_mm),
        ..Correction::default()
    });
    let live = LiveRenderer::new(gpu(), Some(module_cache()), 2);
    let pair = render_pair(
        &live,
        &PairRequest {
            scene: &scene,
            eyes: [&eyes[0], &eyes[1]],
            options: LiveOptions {
                focus: Some(ocular::render::frame_plan::FocusAsked::DistanceM(
                    f64::INFINITY,
                )),
                pupil_mm: Some(3.0),
                ..LiveOptions::default()
            },
            corrections,
            size: SIZE,
            time_s: 0.0,
            ipd_m: DEFAULT_IPD_MM * 1e-3,
        },
    )
    .unwrap();
    // Independently: a thin lens at h = vertex + the entrance pupil's depth magnifies tangents
    // by 1 / (1 − h·P); the depth is the iris (at the lens) imaged back through the cornea.
    let magnification = [0, 1].map(|e| {
        let h_m = (vertex_mm + entrance_pupil_depth_mm(&eyes[e])) * 1e-3;
        1.0 / (1.0 - h_m * powers_d[e])
    });
    let cx = 0.5 * f64::from(SIZE.0);
    let mut offsets = [0.0; 2];
    for e in 0..2 {
        let (x, _) = centroid(&pair.frames[e].color, SIZE.0);
        // each eye sees the marker from its own position (parallax, exact)
        let tangent = (x_m - pair.geometry.unwrap().positions_m[e][0]) / distance_m;
        let expected = focal * magnification[e] * tangent;
        offsets[e] = x - cx;
        assert!(
            (offsets[e] / expected - 1.0).abs() < 0.003,
            "eye {e}: image at {:.3} px from the centre, expected {expected:.3} (M = {:.4})",
            offsets[e],
            magnification[e]
        );
    }
    // The two images differ in size by the ratio of the magnifications (4.1 % here).
    let ratio = offsets[0] / offsets[1];
    let parallax = (x_m - pair.geometry.unwrap().positions_m[0][0])
        / (x_m - pair.geometry.unwrap().positions_m[1][0]);
    let expected = magnification[0] / magnification[1] * parallax;
    assert!(
        (ratio / expected - 1.0).abs() < 0.002,
        "size ratio {ratio:.5}, expected {expected:.5}"
    );
    eprintln!(
        "aniseikonia: M = {magnification:?}; image offsets {offsets:?} px; size ratio {ratio:.5} \
         (expected {expected:.5})"
    );
    // Without the glasses' magnification (the same eyes uncorrected) the sizes would agree to
    // the parallax alone: the control fails the bar.
    assert!((parallax / expected - 1.0).abs() > 0.02);
    let navarro = entrance_pupil_depth_mm(&ocular::eye::Eye::preset("navarro").unwrap());
    assert!(
        (navarro - 3.04).abs() < 0.01,
        "Navarro's entrance pupil at {navarro} mm"
    );
    finish(live.into_context());
}

#[test]
fn a_pair_is_written_as_two_files_side_by_side_or_as_an_anaglyph() {
    let dir = temp_dir("outputs");
    let cache = module_cache();
    let run = |stereo: &str, name: &str| {
        let out = ocular_run(&[
            "render",
            "--scene",
            "primitives",
            "--size",
            "64x36",
            "--binocular",
            "--eye",
            "healthy",
            "--focus-m",
            "0.5",
            "--quality",
            "fast",
            "--cache",
            cache.to_str().unwrap(),
            "--stereo",
            stereo,
            "-o",
            dir.join(name).to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    run("separate", "view.png");
    run("side-by-side", "sbs.png");
    run("anaglyph", "red-cyan.png");
    let load = |name: &str| image::open(dir.join(name)).unwrap().to_rgb8();
    let (left, right) = (load("view-left.png"), load("view-right.png"));
    assert_eq!(left.dimensions(), (64, 36));
    assert_ne!(left, right, "the eyes see from different places");
    let sbs = load("sbs.png");
    assert_eq!(sbs.dimensions(), (128, 36));
    let ana = load("red-cyan.png");
    for y in 0..36 {
        for x in 0..64 {
            assert_eq!(sbs.get_pixel(x, y), left.get_pixel(x, y));
            assert_eq!(sbs.get_pixel(64 + x, y), right.get_pixel(x, y));
            let (a, l, r) = (
                ana.get_pixel(x, y),
                left.get_pixel(x, y),
                right.get_pixel(x, y),
            );
            assert_eq!([a[0], a[1], a[2]], [l[0], r[1], r[2]], "at {x},{y}");
        }
    }
}

/// One view of a synthetic stereo pair: a near card (0.5 m) shifted by `shift` px over a
/// textured wall at 3 m, as (R, G, B, depth) planes.
fn stereo_view((w, h): (usize, usize), shift: usize) -> [Vec<f32>; 4] {
    let mut planes: [Vec<f32>; 4] = Default::default();
    for y in 0..h {
        for x in 0..w {
            let card = (20 + shift..44 + shift).contains(&x) && (12..36).contains(&y);
            let (rgb, d) = if card {
                ([30.0, 6.0, 4.0], 0.5)
            } else {
                let t = 10.0 + 8.0 * ((x as f32 * 0.7).sin() * (y as f32 * 0.5).cos());
                ([t, t * 1.1, t * 0.9], 3.0)
            };
            for c in 0..3 {
                planes[c].push(rgb[c]);
            }
            planes[3].push(d);
        }
    }
    planes
}

fn exr_planes(prefix: &str, depth: &str, planes: &[Vec<f32>; 4]) -> Vec<blender::Plane> {
    ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(c, n)| blender::plane(&format!("{prefix}{n}"), planes[c].clone()))
        .chain([blender::plane(depth, planes[3].clone())])
        .collect()
}

/// Blender's stereoscopy output and OpenEXR's single-part multi-view convention render into
/// the same pair, to the bit, as the same views given one file per eye; views that disagree
/// in size, or a file without views, are refused with one line.
#[test]
fn a_stereo_exr_renders_as_its_two_halves() {
    use exr::prelude::*;
    let dir = temp_dir("stereo");
    let cache = module_cache();
    let size = (64usize, 48usize);
    let (left, right) = (stereo_view(size, 0), stereo_view(size, 3));
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    blender::write_single_part(&dir.join("left.exr"), size, exr_planes("", "Z", &left));
    blender::write_single_part(&dir.join("right.exr"), size, exr_planes("", "Z", &right));
    // Blender: one part per view, its channels named as in a mono multilayer file
    blender::write_views(
        &dir.join("blender.exr"),
        size,
        vec![
            (
                "left",
                "left",
                exr_planes("ViewLayer.Combined.", "ViewLayer.Depth.Z", &left),
            ),
            (
                "right",
                "right",
                exr_planes("ViewLayer.Combined.", "ViewLayer.Depth.Z", &right),
            ),
        ],
    );
    // OpenEXR's single-part convention: the default (first) view's channels unprefixed
    let mut planes = exr_planes("", "Z", &left);
    planes.extend(exr_planes("right.", "right.Z", &right));
    let list: Vec<AnyChannel<FlatSamples>> = planes
        .into_iter()
        .map(|p| AnyChannel::new(p.name.as_str(), FlatSamples::F32(p.values)))
        .collect();
    let attributes = LayerAttributes {
        multi_view_names: Some(vec![Text::from("left"), Text::from("right")]),
        ..Default::default()
    };
    Image::from_layer(Layer::new(
        size,
        attributes,
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(list.into()),
    ))
    .write()
    .to_file(dir.join("views.exr"))
    .unwrap();

    let render = |inputs: &[&str], out: &str| {
        let mut args = vec!["render", "--binocular", "--fov-y", "30"];
        args.extend_from_slice(inputs);
        let cache = cache.to_str().unwrap().to_string();
        let out = path(out);
        args.extend_from_slice(&[
            "--eye",
            "healthy",
            "--eye-right",
            "myopia",
            "--focus-m",
            "0.5",
            "--pupil-mm",
            "4",
            "--quality",
            "fast",
            "--cache",
            &cache,
            "-o",
            &out,
        ]);
        ocular_run(&args)
    };
    let (l, r) = (path("left.exr"), path("right.exr"));
    let halves = render(&["--color", &l, "--color-right", &r], "halves.exr");
    assert!(
        halves.status.success(),
        "{}",
        String::from_utf8_lossy(&halves.stderr)
    );
    let bytes = |name: &str| std::fs::read(dir.join(name)).unwrap();
    assert_ne!(
        bytes("halves-left.exr"),
        bytes("halves-right.exr"),
        "each eye sees its own view"
    );
    for file in ["blender.exr", "views.exr"] {
        let stem = file.trim_end_matches(".exr").to_string() + "-out.exr";
        let out = render(&["--color", &path(file)], &stem);
        assert!(
            out.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        for side in ["left", "right"] {
            let got = stem.replace(".exr", &format!("-{side}.exr"));
            assert!(
                bytes(&got) == bytes(&format!("halves-{side}.exr")),
                "{file}: the {side} eye's frame differs from its half's"
            );
        }
    }
    // refusals: a single-view file as a pair, and views of two sizes
    let one = render(&["--color", &l], "one.exr");
    assert_eq!(one.status.code(), Some(2));
    let text = String::from_utf8_lossy(&one.stderr);
    assert!(
        text.contains("has no views") && text.lines().count() == 1,
        "{text}"
    );
    let small = stereo_view((32, 24), 0);
    blender::write_single_part(
        &dir.join("small.exr"),
        (32, 24),
        exr_planes("", "Z", &small),
    );
    let sizes = render(
        &["--color", &l, "--color-right", &path("small.exr")],
        "sizes.exr",
    );
    assert_eq!(sizes.status.code(), Some(2));
    let text = String::from_utf8_lossy(&sizes.stderr);
    assert!(
        text.contains("64×48") && text.contains("32×24") && text.lines().count() == 1,
        "{text}"
    );
    assert!(!dir.join("sizes-left.exr").exists() && !dir.join("one-left.exr").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An eye made hyperopic by a minus contact lens: its far point lies beyond infinity, by the
/// lens's power (a thin lens on the cornea, where vergences are counted, adds its power to
/// every vergence: the oracle, written here). Fixating far beside a partner that sees sharp
/// for free, it is left relaxed and blurred, as the more hyperopic eye of a pair is; the old
/// far point clamped at 0 D rendered it accommodated and sharp (the negative control).
#[test]
fn an_over_minused_eye_keeps_its_far_point_beyond_infinity_and_stays_blurred() {
    use ocular::render::binocular::{render_pair, PairRequest};
    use ocular::render::frame_plan::{Correction, FocusAsked};
    use ocular::render::live::{LiveOptions, LiveRenderer, SceneArg};

    let eye = ocular::eye::Eye::preset("healthy").unwrap();
    let contact = |p: f64| Correction {
        spectacle: Some(ocular::eye::Spectacle::new(p, 0.0, 180.0, 0.0).unwrap()),
        contact: true,
        ..Correction::default()
    };
    let live = LiveRenderer::new(gpu(), Some(module_cache()), 4);
    let mut raster = Rasterizer::new(live.context()).unwrap();
    let focus_m = 6.0;
    let scene = letter_scene(focus_m);
    let options = LiveOptions {
        focus: Some(FocusAsked::DistanceM(focus_m)),
        pupil_mm: Some(5.0),
        age: 30.0,
        ..LiveOptions::default()
    };
    let pair = render_pair(
        &live,
        &PairRequest {
            scene: &scene,
            eyes: [&eye, &eye],
            options: options.clone(),
            corrections: [contact(0.0), contact(-1.75)],
            size: (192, 108),
            time_s: 0.0,
            ipd_m: 0.063,
        },
    )
    .unwrap();
    // The left eye's far point is found where it lies (before the eye), the right one's
    // extrapolated beyond infinity: they differ by the lens.
    let [left_fp, right_fp] = pair.far_point_d;
    assert!(left_fp >= 0.0, "{left_fp}");
    assert!(
        (right_fp - (left_fp - 1.75)).abs() < 0.01,
        "far points {left_fp:.4} D and {right_fp:.4} D: expected {:.4} D",
        left_fp - 1.75
    );
    // The left eye misses 6 m by under 0.125 D relaxed: it drives, with no accommodation, and
    // the right eye stays relaxed, 1.75 D + the demand short of the letter.
    let demand = pair.demand_d[1];
    assert_eq!(pair.yoke.driver, 0, "{:?}", pair.yoke);
    assert!(pair.yoke.accommodation_d.abs() < 1e-9, "{:?}", pair.yoke);
    assert!((pair.yoke.focus_d[1] - right_fp).abs() < 1e-9);
    assert!((pair.yoke.residual_d[1] - (demand - right_fp)).abs() < 1e-9);
    let scale = 2f32.powf(pair.exposure_ev);
    let camera = pair.geometry.unwrap().cameras[1];
    let right_eye = |o: LiveOptions| {
        live.render_scene_from(
            SceneArg::Loaded(&scene),
            &eye,
            &o,
            Some((192, 108)),
            0.0,
            Some(camera),
        )
        .unwrap()
        .0
        .color
    };
    let shown = LiveOptions {
        exposure_ev: Some(f64::from(pair.exposure_ev)),
        ..options.clone()
    };
    // The relaxed right eye: no accommodation at all, the letter asked.
    let relaxed = right_eye(LiveOptions {
        correction: Correction {
            accommodation_max_d: Some(0.0),
            ..contact(-1.75)
        },
        ..shown.clone()
    });
    // What the clamped far point rendered: the eye accommodating onto the letter.
    let accommodated = right_eye(LiveOptions {
        correction: contact(-1.75),
        ..shown.clone()
    });
    let letter = (72, 120);
    let same = region_psnr(&pair.frames[1].color, &relaxed, (0, 192), scale);
    let old = region_psnr(&pair.frames[1].color, &accommodated, letter, scale);
    let mut state = scene.at_time(0.0);
    state.camera = camera;
    let sharp = raster.render(live.context(), &state, 192, 108).unwrap();
    let [right_q, accommodated_q] =
        [&pair.frames[1].color, &accommodated].map(|c| region_psnr(c, &sharp.color, letter, scale));
    eprintln!(
        "far points {left_fp:.4} / {right_fp:.4} D; right frame vs relaxed {same:.1} dB, vs \
         accommodated {old:.1} dB; letter vs sharp: right {right_q:.1} dB, accommodated \
         {accommodated_q:.1} dB"
    );
    assert!(
        same > 60.0,
        "the right frame is not the relaxed eye's: {same:.1} dB"
    );
    assert!(
        old < 30.0,
        "the relaxed and accommodated eyes look alike: {old:.1} dB"
    );
    assert!(
        accommodated_q > right_q + 6.0,
        "{accommodated_q:.1} vs {right_q:.1} dB"
    );
    // The summary counts the far point beyond infinity in the right frame's report too.
    assert!((pair.frames[1].report.far_point_d - right_fp).abs() < 1e-12);
    drop(raster);
    finish(live.into_context());
}

/// `ocular bench --binocular` times both eyes in the same run as one: each pair is two
/// submissions, and its work is both eyes' (each eye's frame, from 31.5 mm to the side, costs
/// about what the camera's does: a pair that rendered one eye twice over, or one eye only,
/// would miss the bounds). Its times are reported, not asserted (docs/binocular.md, "Cost").
#[test]
fn bench_times_a_pair_beside_one_eye() {
    let dir = temp_dir("binocular-bench");
    let path = dir.join("bench.json");
    let out = ocular_run(&[
        "bench",
        "--scene",
        "primitives",
        "--eye",
        "myopia",
        "--size",
        "160x90",
        "--warmup",
        "1",
        "--frames",
        "1",
        "--binocular",
        "--eye-right",
        "healthy",
        "--json",
        path.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("two eyes"));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let pair = &r["binocular"];
    assert_eq!(pair["submissions"], 2, "{pair}");
    assert_eq!(pair["eye_right"], "healthy");
    assert_eq!(pair["ipd_mm"], 63.0);
    let one = r["kernel_evaluations"].as_f64().unwrap();
    let both = pair["kernel_evaluations"].as_f64().unwrap();
    // the healthy right eye blurs less than the myopic left: more than one eye's work, less
    // than two myopic eyes'
    assert!(
        both > 1.05 * one && both < 2.0 * one,
        "one eye {one}, pair {both}"
    );
    // Times are reported, not asserted: one timed frame per side, on a runner that runs other
    // tests beside it, can come out either way.
    for k in ["gpu_ratio", "wall_ratio"] {
        let ratio = pair[k].as_f64().unwrap();
        assert!(ratio.is_finite() && ratio > 0.0, "{k}: {pair}");
    }
}

/// A pseudophakic monovision pair: both crystalline lenses replaced, the left by the IOL that
/// makes the eye emmetropic, the right by one 2.5 D stronger, so that it is myopic by about
/// 1.8 D. Neither accommodates: each eye stays at its own far point whatever the target, the
/// far letter sharp in the left eye and the near one in the right. The negative control is the
/// pair with one IOL for both (what `--iol-d` alone gives), which sees the near letter sharp in
/// neither eye.
#[test]
fn a_pseudophakic_monovision_pair_sees_far_with_one_eye_and_near_with_the_other() {
    use ocular::render::binocular::{render_pair, PairRequest};
    use ocular::render::frame_plan::{Correction, FocusAsked, IolPower};
    use ocular::render::live::{LiveOptions, LiveRenderer};

    let eye = ocular::eye::Eye::preset("healthy").unwrap();
    let live = LiveRenderer::new(gpu(), Some(module_cache()), 4);
    let mut raster = Rasterizer::new(live.context()).unwrap();
    let iol = |power: IolPower| Correction {
        iol: Some(power),
        ..Correction::default()
    };
    let auto_d = ocular::render::frame_plan::corrected_eye(&eye, &iol(IolPower::Auto), None)
        .unwrap()
        .1
        .iol_d
        .unwrap();
    let monovision = [iol(IolPower::Auto), iol(IolPower::Dioptres(auto_d + 2.5))];
    let same = [iol(IolPower::Auto), iol(IolPower::Auto)];
    let letter = (72, 120);
    // Per target distance, per pair: the letter's PSNR against the sharp frame in each eye.
    let mut seen = Vec::new();
    for focus_m in [6.0, 0.5] {
        let scene = letter_scene(focus_m);
        for corrections in [monovision.clone(), same.clone()] {
            let pair = render_pair(
                &live,
                &PairRequest {
                    scene: &scene,
                    eyes: [&eye, &eye],
                    options: LiveOptions {
                        focus: Some(FocusAsked::DistanceM(focus_m)),
                        pupil_mm: Some(4.0),
                        age: 70.0,
                        ..LiveOptions::default()
                    },
                    corrections,
                    size: (192, 108),
                    time_s: 0.0,
                    ipd_m: 0.063,
                },
            )
            .unwrap();
            assert_eq!(pair.amplitude_d, [Some(0.0), Some(0.0)]);
            assert_eq!(pair.yoke.accommodation_d, 0.0);
            assert_eq!(pair.yoke.focus_d, pair.far_point_d);
            let scale = 2f32.powf(pair.exposure_ev);
            let q = [0, 1].map(|e| {
                let mut state = scene.at_time(0.0);
                state.camera = pair.geometry.unwrap().cameras[e];
                let sharp = raster.render(live.context(), &state, 192, 108).unwrap();
                region_psnr(&pair.frames[e].color, &sharp.color, letter, scale)
            });
            seen.push((focus_m, pair.far_point_d, q));
        }
    }
    eprintln!("(target m, far points D, letter dB per eye): {seen:?}");
    let [(_, far_points, far_mono), (_, _, far_same), (_, _, near_mono), (_, _, near_same)] =
        seen[..]
    else {
        unreachable!()
    };
    // The stronger IOL makes the right eye myopic by about 0.7 of its extra power: a thin
    // lens a reduced distance t behind a cornea of power K adds (1 − t·K)² of its power at
    // the cornea, 0.70 for t = 5 mm / 1.336 and K = 43 D (1.76 D; the traced eye: 1.86 D).
    assert!(far_points[0].abs() < 0.25, "{far_points:?}");
    let myopia = far_points[1] - far_points[0];
    assert!((1.5..2.2).contains(&myopia), "{far_points:?}");
    assert!(far_mono[0] > far_mono[1] + 6.0, "far: {far_mono:?}");
    assert!(near_mono[1] > near_mono[0] + 6.0, "near: {near_mono:?}");
    // One IOL for both: near, neither eye sees the letter as the monovision right eye does.
    assert!(
        near_same[0].max(near_same[1]) < near_mono[1] - 6.0,
        "near, one IOL: {near_same:?} against {near_mono:?}"
    );
    assert!((far_same[0] - far_same[1]).abs() < 1.0, "{far_same:?}");
    drop(raster);
    finish(live.into_context());
}

/// The far point beyond infinity is extrapolated from c(2,0) at 0, 1 and 2 D; a thin contact
/// lens on the cornea adds its power to every vergence, so a myopic eye behind ever stronger
/// minus lenses has its far point move by exactly the lens's power: the oracle, from 1 D to
/// 10 D beyond infinity (the secant finds the bare eye's, before it).
#[test]
fn far_points_beyond_infinity_follow_the_lens_to_10_dioptres() {
    use ocular::psf::KernelSettings;
    use ocular::render::frame_plan::{corrected_eye, Correction};
    use ocular::render::signed_far_point_d;

    let eye = ocular::eye::Eye::preset("myopia").unwrap();
    let settings = KernelSettings::default();
    let pupil_mm = 4.0;
    let bare = signed_far_point_d(&eye, pupil_mm, &settings).unwrap();
    assert!(bare > 5.0, "{bare}");
    let mut worst: f64 = 0.0;
    for beyond_d in [1.0, 2.5, 5.0, 10.0] {
        let lens_d = -(bare + beyond_d);
        let correction = Correction {
            spectacle: Some(ocular::eye::Spectacle::new(lens_d, 0.0, 180.0, 0.0).unwrap()),
            contact: true,
            ..Correction::default()
        };
        let (lensed, _) = corrected_eye(&eye, &correction, None).unwrap();
        let far = signed_far_point_d(&lensed, pupil_mm, &settings).unwrap();
        let error = far - (bare + lens_d);
        eprintln!("{beyond_d} D beyond infinity: {far:.5} D, error {error:+.2e} D");
        worst = worst.max(error.abs() / beyond_d);
    }
    // measured: 1.9e-4 D at 1 D, 6.4e-3 D at 10 D (6.4e-4 of the distance beyond infinity);
    // the far point clamped at 0 D, as before, would be off by all of it
    assert!(worst < 1e-3, "relative error {worst:.2e}");
}

/// A headset's frame (`--headset`): the panel's size, the scene's camera at the headset's
/// vertical field for the whole animation (a keyframed field is dropped), and a point 20° to
/// the right and 30° up landing where a pinhole of that field puts it, at f·tan θ from the
/// centre with f = (H/2)/tan(fov/2) written here.
#[test]
fn a_headset_frame_has_its_panel_and_its_field() {
    use ocular::render::headset::Headset;
    let spec = Headset::VivePro.spec();
    assert_eq!(spec.size(), (1440, 1600));
    // A marker scene whose field is keyframed (20° → 40°): the headset's field replaces both.
    let scene = |x_deg: f64, y_deg: f64| {
        let d = 3.0;
        let (x, y) = (d * x_deg.to_radians().tan(), d * y_deg.to_radians().tan());
        let keyed = "[[keyframe]]\ntime_s = 1.0\ncamera = { fov_y_deg = 40.0 }\n";
        sphere_scene([x, y, -d], 0.03, keyed).with_fov_y_deg(spec.fov_y_deg)
    };
    let ctx = gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let (w, h) = spec.size();
    let focal = 0.5 * f64::from(h) / (0.5 * 110f64).to_radians().tan();
    for (x_deg, y_deg, t) in [(0.0, 0.0, 0.0), (20.0, 30.0, 1.0), (-35.0, -10.0, 0.5)] {
        let s = scene(x_deg, y_deg);
        let state = s.at_time(t);
        assert_eq!(state.camera.fov_y_deg, 110.0, "t = {t}");
        let frame = raster.render(&ctx, &state, w, h).unwrap();
        let (x, y) = centroid(&frame.color, w);
        // The sphere's centre projects to (f·tan θx, −f·tan θy) from the centre; the
        // silhouette's centroid of a small off-axis sphere lies a little farther out, by the
        // sphere's angular radius squared times tan θ (0.01² rad²): 0.08 px at most here.
        let ex = 0.5 * f64::from(w) + focal * x_deg.to_radians().tan();
        let ey = 0.5 * f64::from(h) - focal * y_deg.to_radians().tan();
        assert!(
            (x - ex).abs() <= 0.15 && (y - ey).abs() <= 0.15,
            "marker at ({x_deg}°, {y_deg}°): ({x:.3}, {y:.3}), expected ({ex:.3}, {ey:.3})"
        );
    }
    drop(raster);
    finish(ctx);
}

/// `render --binocular --headset`: both eyes at the headset's panel, its fields in the JSON
/// summary (the horizontal one from the panel's aspect, computed here), and `--size` refused
/// beside it.
#[test]
fn render_writes_a_pair_at_a_headset_panel() {
    let dir = temp_dir("headset");
    let cache = module_cache();
    let out = dir.join("vr.png");
    let r = json(&[
        "render",
        "--scene",
        "primitives",
        "--binocular",
        "--headset",
        "vive-pro",
        "--quality",
        "fast",
        "--stereo",
        "anaglyph",
        "--cache",
        cache.to_str().unwrap(),
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        (r["width"].as_u64(), r["height"].as_u64()),
        (Some(1440), Some(1600))
    );
    let headset = &r["headset"];
    assert_eq!(headset["preset"], "vive-pro");
    assert_eq!(headset["fov_y_deg"].as_f64(), Some(110.0));
    let fov_x = 2.0
        * ((55f64).to_radians().tan() * 1440.0 / 1600.0)
            .atan()
            .to_degrees();
    assert!((headset["fov_x_deg"].as_f64().unwrap() - fov_x).abs() < 1e-9);
    assert!((headset["frame_budget_ms"].as_f64().unwrap() - 1000.0 / 90.0).abs() < 1e-9);
    assert_eq!(
        image::open(&out).unwrap().to_rgb8().dimensions(),
        (1440, 1600)
    );
    let refused = ocular_run(&[
        "render",
        "--headset",
        "quest3",
        "--size",
        "64x36",
        "-o",
        dir.join("x.png").to_str().unwrap(),
    ]);
    assert_eq!(refused.status.code(), Some(2));
    let text = String::from_utf8_lossy(&refused.stderr);
    assert!(
        text.contains("--headset") && text.contains("--size"),
        "{text}"
    );
    assert!(!dir.join("x.png").exists());
}

/// An EXR's pixels (linear RGBA).
fn exr_pixels(path: &std::path::Path) -> Vec<[f32; 4]> {
    ocular::image_io::read_exr_rgba(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .pixels
}

/// PSNR (dB) of `a` against `reference`, over RGB, at the reference's peak.
fn psnr_at_peak(a: &[[f32; 4]], reference: &[[f32; 4]]) -> f64 {
    let peak = reference
        .iter()
        .flat_map(|p| p[..3].iter().copied())
        .fold(0.0f32, f32::max);
    let scaled = |v: &[[f32; 4]]| -> Vec<[f32; 4]> {
        v.iter()
            .map(|p| [p[0] / peak, p[1] / peak, p[2] / peak, 1.0])
            .collect()
    };
    crate::common::pixels::psnr(&scaled(a), &scaled(reference))
}

/// `ocular video --binocular` renders, at each instant, the pair `ocular render --binocular`
/// makes for that instant's focus: a monovision pair (the healthy eye on the left, one estimated
/// from "-1.5" on the right, 55 years old) through a focus sweep from 0.4 m to 6 m. One frame
/// alone is the render's pair to the bit (both plan the same kernels), in every layout. Over
/// the sweep each frame's kernels are planned for the whole sweep, so a frame is held to the
/// render for its own focus within that planning (50 dB); the negative control, the frame
/// judged against the render for the sweep's other end (other vergence, the other eye
/// driving), falls at least 15 dB below.
#[test]
fn a_binocular_video_is_the_pair_render_makes_at_each_instant() {
    let dir = temp_dir("video-pair");
    let cache = module_cache();
    let near_eye = estimated_eye(&dir, "-1.5");
    let common = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = [
            "--scene",
            "chart",
            "--size",
            "192x108",
            "--eye",
            "healthy",
            "--eye-right",
            near_eye.to_str().unwrap(),
            "--age",
            "55",
            "--pupil-mm",
            "3",
            "--cache",
            cache.to_str().unwrap(),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let run = |args: Vec<String>| {
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = ocular_run(&refs);
        assert!(
            out.status.success(),
            "{refs:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    };
    let render_pair = |focus_m: &str, name: &str| -> [Vec<[f32; 4]>; 2] {
        let output = dir.join(format!("{name}.exr"));
        let mut args = vec!["render".to_string(), "--binocular".into()];
        args.extend(common(&[
            "--focus-m",
            focus_m,
            "-o",
            output.to_str().unwrap(),
        ]));
        run(args);
        ["left", "right"].map(|side| exr_pixels(&dir.join(format!("{name}-{side}.exr"))))
    };
    let video = |extra: &[&str], folder: &str| -> std::path::PathBuf {
        let out = dir.join(folder);
        let mut args = vec!["video".to_string(), "--binocular".into()];
        args.extend(common(extra));
        args.extend(["--format", "exr", "-o", out.to_str().unwrap()].map(String::from));
        run(args);
        out
    };

    // One frame, the scene's own focus (its chart at 6 m): the render's pair to the bit.
    let still = render_pair("6", "still");
    let separate = video(&["--duration", "0", "--stereo", "separate"], "one");
    for (e, side) in ["left", "right"].iter().enumerate() {
        let frame = exr_pixels(&separate.join(format!("frame_000000-{side}.exr")));
        assert!(
            frame == still[e],
            "{side}: the video's frame is not the render's"
        );
    }
    let sbs = exr_pixels(&video(&["--duration", "0"], "sbs").join("frame_000000.exr"));
    let (w, h) = (192usize, 108usize);
    for y in 0..h {
        assert!(sbs[y * 2 * w..y * 2 * w + w] == still[0][y * w..(y + 1) * w]);
        assert!(sbs[y * 2 * w + w..(y + 1) * 2 * w] == still[1][y * w..(y + 1) * w]);
    }
    let anaglyph = exr_pixels(
        &video(&["--duration", "0", "--stereo", "anaglyph"], "ana").join("frame_000000.exr"),
    );
    assert!(anaglyph
        .iter()
        .zip(still[0].iter().zip(&still[1]))
        .all(|(a, (l, r))| a[0] == l[0] && a[1] == r[1] && a[2] == r[2]));

    // The sweep: 3 frames, focused at 2.5, 1.33 and 0.17 D (linear in dioptres).
    let sweep = video(
        &[
            "--focus-sweep",
            "0.4..6",
            "--fps",
            "1",
            "--duration",
            "3",
            "--stereo",
            "separate",
        ],
        "sweep",
    );
    let near = render_pair("0.4", "near");
    let far = render_pair("6", "far");
    let frame = |i: usize, side: &str| exr_pixels(&sweep.join(format!("frame_{i:06}-{side}.exr")));
    let mut report = Vec::new();
    for (i, own, other) in [(0, &near, &far), (2, &far, &near)] {
        for (e, side) in ["left", "right"].iter().enumerate() {
            let f = frame(i, side);
            let (same, control) = (psnr_at_peak(&f, &own[e]), psnr_at_peak(&f, &other[e]));
            report.push(format!(
                "frame {i} {side}: {same:.1} dB, other end {control:.1} dB"
            ));
            assert!(
                same > 50.0,
                "frame {i} {side}: {same:.1} dB from its own focus's render"
            );
            assert!(
                control < same - 15.0,
                "frame {i} {side}: {control:.1} dB from the other end's render"
            );
        }
    }
    eprintln!("{}", report.join("; "));
}

/// The pair's options in `video`: each misuse is refused, exit 2, its first line naming the
/// option.
#[test]
fn video_pair_options_are_checked() {
    let dir = temp_dir("video-pair-options");
    let out = dir.join("v");
    let o = out.to_str().unwrap();
    for (args, expected) in [
        (vec!["--ipd-mm", "60"], "--ipd-mm applies to two eyes"),
        (
            vec!["--binocular", "--side-by-side", "myopia"],
            "--side-by-side",
        ),
        (vec!["--binocular", "--off-axis"], "--off-axis"),
        (vec!["--binocular", "--ipd-mm", "90"], "--ipd-mm 90"),
        (
            vec!["--binocular", "--stereo", "separate", "--mp4", "x.mp4"],
            "--mp4",
        ),
        (vec!["--headset", "quest3"], "--size"),
    ] {
        let mut full = vec!["video", "--scene", "chart", "--size", "32x18", "-o", o];
        full.extend(&args);
        let run = ocular_run(&full);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {stderr}");
        // the reason on the first line (clap adds its usage below a conflict)
        let first = stderr.lines().next().unwrap_or_default();
        assert!(first.contains(expected), "{args:?}: {stderr}");
    }
}

/// `video --headset` renders each frame at the headset's panel, both eyes side by side with
/// `--binocular`, and records the panel in the export's manifest.
#[test]
fn a_video_pair_is_rendered_at_a_headset_panel() {
    let dir = temp_dir("video-headset");
    let cache = module_cache();
    let out = dir.join("vr");
    let run = ocular_run(&[
        "video",
        "--scene",
        "primitives",
        "--binocular",
        "--headset",
        "vive-pro",
        "--quality",
        "fast",
        "--duration",
        "0",
        "--cache",
        cache.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(
        image::open(out.join("frame_000000.png"))
            .unwrap()
            .to_rgb8()
            .dimensions(),
        (2 * 1440, 1600)
    );
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("ocular-video.json")).unwrap())
            .unwrap();
    assert_eq!(manifest["config"]["size"], serde_json::json!([1440, 1600]));
    assert_eq!(manifest["config"]["binocular"]["stereo"], "side-by-side");
}

/// An eye whose yoked focus lies beyond infinity (the healthy eye in a −1.75 D contact lens
/// beside the same eye in a plano one, the chart at 6 m: the left eye drives relaxed) is
/// rendered by the video as `render --binocular` renders it, at the accommodation it exerts,
/// to the bit: the video's kernels of its own for that eye.
#[test]
fn a_video_eye_beyond_infinity_is_the_renders() {
    let dir = temp_dir("video-beyond");
    let cache = module_cache();
    let cache = cache.to_str().unwrap();
    let options = [
        "--scene",
        "chart",
        "--binocular",
        "--eye",
        "healthy",
        "--correct",
        "0",
        "--correct-contact",
        "--correct-right",
        "-1.75",
        "--pupil-mm",
        "5",
        "--size",
        "96x54",
        "--cache",
        cache,
    ];
    let render_out = dir.join("r.exr");
    let mut render = vec!["render", "--json", "-o", render_out.to_str().unwrap()];
    render.extend(options);
    let summary = json(&render);
    let right_focus = summary["eyes"][1]["focus_d"].as_f64().unwrap();
    assert!(right_focus < -1.0, "the right eye's focus {right_focus} D");
    let video_out = dir.join("v");
    let mut video = vec![
        "video",
        "--duration",
        "0",
        "--format",
        "exr",
        "--stereo",
        "separate",
        "-o",
        video_out.to_str().unwrap(),
    ];
    video.extend(options);
    let out = ocular_run(&video);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for side in ["left", "right"] {
        let v = exr_pixels(&video_out.join(format!("frame_000000-{side}.exr")));
        let r = exr_pixels(&dir.join(format!("r-{side}.exr")));
        assert!(v == r, "{side}: the video's frame is not the render's");
    }
}

/// `ocular compare --binocular` judges each eye of a pair against that eye's own truth: the
/// pair stands and accommodates as `render --binocular` puts it (the same yoke: driver and
/// each eye's focus), each eye's splat is held to its truth as one eye's is, and the two
/// truths are two eyes' (the negative control: one eye's truth judged against the other's is
/// far from either splat's score).
#[test]
fn compare_judges_each_eye_of_a_pair_against_its_own_truth() {
    let dir = temp_dir("compare-pair");
    let cache = module_cache();
    let cache = cache.to_str().unwrap();
    let pair = [
        "--scene",
        "chart",
        "--eye",
        "healthy",
        "--eye-right",
        "myopia",
        "--size",
        "96x54",
        "--pupil-mm",
        "4",
        "--cache",
        cache,
    ];
    let report = dir.join("pair.json");
    let truth = dir.join("truth.exr");
    let mut compare = vec![
        "compare",
        "--no-slices",
        "--json",
        report.to_str().unwrap(),
        "--truth-out",
        truth.to_str().unwrap(),
    ];
    compare.extend(pair);
    let out = ocular_run(&compare);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let render_out = dir.join("r.png");
    let mut render = vec!["render", "--json", "-o", render_out.to_str().unwrap()];
    render.extend(pair);
    let rendered = json(&render);
    assert_eq!(
        report["binocular"]["driver"], rendered["driver"],
        "{report}"
    );
    let mut splat_db = Vec::new();
    for e in 0..2 {
        let eye = &report["eyes"][e];
        assert_eq!(eye["side"], ["left", "right"][e]);
        let want = rendered["eyes"][e]["focus_d"].as_f64().unwrap();
        let got = eye["focus_d"].as_f64().unwrap();
        assert!(
            (got - want).abs() < 1e-9,
            "eye {e}: focus {got} D, render's {want} D"
        );
        let splat = eye["methods"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["method"] == "splat")
            .unwrap();
        let db = splat["psnr_db"].as_f64().unwrap();
        assert!(db > 60.0, "eye {e}: splat {db:.1} dB from its truth");
        splat_db.push(db);
    }
    let [left, right] = ["left", "right"].map(|s| exr_pixels(&dir.join(format!("truth-{s}.exr"))));
    let across = psnr_at_peak(&left, &right);
    eprintln!("splat {splat_db:?} dB against each eye's truth; the truths {across:.1} dB apart");
    assert!(
        across < 40.0,
        "the two eyes' truths are {across:.1} dB apart"
    );
    // what judges one eye's frame only is refused with a pair
    let mut refused = compare.clone();
    refused.extend(["--truth-in", truth.to_str().unwrap()]);
    let out = ocular_run(&refused);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--truth-in judges one eye's frame"));
}
