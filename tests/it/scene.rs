//! Scene files, OBJ loading and animation, on the CPU: what parses, what is rejected and with
//! which file and line, and how keyframes interpolate.

use crate::common::data;
use std::path::Path;

use ocular::scene::obj;
use ocular::scene::optotype::letter_height_m;
use ocular::scene::{Scene, Track};
use ocular::Error;

/// The error's file and message, asserting it is a file error (exit code 2).
fn file_error(result: Result<impl std::fmt::Debug, Error>) -> (String, String) {
    let err = result.expect_err("expected an error");
    assert_eq!(err.exit_code(), 2, "{err}");
    match err {
        Error::File { path, message } => (path, message),
        other => panic!("expected a file error, got {other}"),
    }
}

#[test]
fn obj_handles_mtl_colours_ngons_negative_indices_and_missing_normals() {
    let parts = obj::load(&data("shapes.obj")).unwrap();
    assert_eq!(parts.len(), 2, "{parts:?}");
    let pentagon = &parts[0];
    assert_eq!(pentagon.name, "pentagon");
    // A pentagon written with negative indices becomes a fan of 3 triangles.
    assert_eq!(pentagon.mesh.indices.len(), 9);
    assert_eq!(
        pentagon.diffuse,
        Some([0.9f32 as f64, 0.1f32 as f64, 0.05f32 as f64])
    );
    // No normals in the file: flat face normals, here ±Z for a polygon in the XY plane.
    for n in &pentagon.mesh.normals {
        assert!(
            (n[2].abs() - 1.0).abs() < 1e-12 && n[0] == 0.0 && n[1] == 0.0,
            "{n:?}"
        );
    }
    // The fan covers the pentagon's area exactly (shoelace formula on the 5 vertices).
    let p = &pentagon.mesh.positions;
    let area: f64 = pentagon
        .mesh
        .indices
        .chunks(3)
        .map(|t| {
            let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
            0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs()
        })
        .sum();
    let poly = [[0.0, 0.0], [1.0, 0.0], [1.3, 1.0], [0.5, 1.6], [-0.3, 1.0]];
    let shoelace: f64 = 0.5
        * (0..5)
            .map(|i| {
                let (a, b) = (poly[i], poly[(i + 1) % 5]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>()
            .abs();
    assert!((area - shoelace).abs() < 1e-6, "{area} vs {shoelace}");

    let triangle = &parts[1];
    assert_eq!(
        triangle.diffuse,
        Some([0.05f32 as f64, 0.1f32 as f64, 0.8f32 as f64])
    );
    assert_eq!(triangle.mesh.indices.len(), 3);
    assert!(triangle.mesh.normals.iter().all(|n| *n == [0.0, 0.0, 1.0]));
    // OBJ's v runs up, images run down: v = 1 becomes row 0.
    assert!(
        triangle.mesh.uvs.contains(&[0.0, 0.0]),
        "{:?}",
        triangle.mesh.uvs
    );

    // Through a scene file: two materials with the MTL colours.
    let scene = Scene::from_file(&data("shapes_scene.toml")).unwrap();
    let albedos: Vec<[f32; 3]> = scene.geometry.materials.iter().map(|m| m.albedo).collect();
    assert_eq!(albedos, [[0.9, 0.1, 0.05], [0.05, 0.1, 0.8]]);
    assert_eq!(scene.geometry.triangle_count(), 4);
}

#[test]
fn malformed_obj_and_mtl_name_file_and_line() {
    let (path, message) = file_error(obj::load(&data("bad_face.obj")));
    assert!(path.ends_with("bad_face.obj"), "{path}");
    assert!(
        message.contains("line 5") && message.contains("9"),
        "{message}"
    );

    let (path, message) = file_error(obj::load(&data("bad_vertex.obj")));
    assert!(path.ends_with("bad_vertex.obj"), "{path}");
    assert!(
        message.contains("line 3") && message.contains("vertex"),
        "{message}"
    );

    // The last line, without a trailing newline.
    let (_, message) = file_error(obj::load(&data("bad_last_line.obj")));
    assert!(message.contains("line 3"), "{message}");

    let (path, message) = file_error(obj::load(&data("missing_mtl.obj")));
    assert!(path.ends_with("missing_mtl.obj"), "{path}");
    assert!(
        message.contains("line 2")
            && message.contains("nowhere.mtl")
            && message.contains("not found"),
        "{message}"
    );

    let (path, message) = file_error(obj::load(&data("bad_mtl.obj")));
    assert!(path.ends_with("bad.mtl"), "{path}");
    assert!(
        message.contains("line 3") && message.contains("colour"),
        "{message}"
    );

    let (path, message) = file_error(obj::load(&data("no_such.obj")));
    assert!(
        path.ends_with("no_such.obj") && message.contains("not found"),
        "{message}"
    );
}

#[test]
fn missing_or_broken_textures_name_the_texture_and_where_it_was_named() {
    for (obj_name, texture, mtl, problem) in [
        (
            "missing_texture.obj",
            "not_here.png",
            "missing_texture.mtl",
            "not found",
        ),
        (
            "broken_texture.obj",
            "broken.png",
            "broken_texture.mtl",
            "cannot decode",
        ),
    ] {
        let scene_text = format!(
            "[camera]\nposition = [0.0, 0.0, 2.0]\n\n[[object]]\nkind = \"obj\"\nfile = \"{obj_name}\"\n"
        );
        let (path, message) = file_error(Scene::from_toml(&scene_text, "texture test", &data("")));
        assert!(path.ends_with(texture), "{path}");
        assert!(
            message.contains(problem) && message.contains(mtl) && message.contains("line 3"),
            "{message}"
        );
    }
    // A texture named by the scene itself: the scene file and its line.
    let text = "[camera]\nposition = [0.0, 0.0, 2.0]\n\n[[object]]\nkind = \"plane\"\ntexture = \"gone.png\"\n";
    let (path, message) = file_error(Scene::from_toml(text, "scene.toml", &data("")));
    assert!(path.ends_with("gone.png"), "{path}");
    assert!(message.contains("scene.toml line 4"), "{message}");
}

#[test]
fn malformed_scene_files_name_file_line_and_what_is_allowed() {
    let (path, message) = file_error(Scene::from_file(&data("bad_syntax.toml")));
    assert!(path.ends_with("bad_syntax.toml"), "{path}");
    assert!(message.contains("line 5"), "{message}");

    let (path, message) = file_error(Scene::from_file(&data("bad_field.toml")));
    assert!(path.ends_with("bad_field.toml"), "{path}");
    assert!(
        message.contains("line 7") && message.contains("raduis") && message.contains("radius_m"),
        "{message}"
    );

    let (_, message) = file_error(Scene::from_file(&data("bad_kind.toml")));
    assert!(
        message.contains("line 5") && message.contains("cone") && message.contains("sphere"),
        "{message}"
    );

    // An OBJ error surfaces with the OBJ's own file and line.
    let (path, message) = file_error(Scene::from_file(&data("bad_obj_scene.toml")));
    assert!(
        path.ends_with("bad_face.obj") && message.contains("line 5"),
        "{path}: {message}"
    );

    let (path, message) = file_error(Scene::from_file(&data("missing_obj_scene.toml")));
    assert!(
        path.ends_with("no_such_model.obj")
            && message.contains("not found")
            && message.contains("missing_obj_scene.toml line 4"),
        "{message}"
    );

    let (path, message) = file_error(Scene::from_file(&data("no_such_scene.toml")));
    assert!(
        path.ends_with("no_such_scene.toml") && message.contains("not found"),
        "{message}"
    );

    // A field that exists but not for this kind of object.
    let text =
        "[camera]\nposition = [0.0, 0.0, 0.0]\n\n[[object]]\nkind = \"cube\"\nradius_m = 1.0\n";
    let (_, message) = file_error(Scene::from_toml(text, "x.toml", Path::new(".")));
    assert!(
        message.contains("line 4") && message.contains("radius_m") && message.contains("size_m"),
        "{message}"
    );
    // Out-of-range values.
    let text = "[camera]\nposition = [0.0, 0.0, 0.0]\nfov_y_deg = 200.0\n";
    let (_, message) = file_error(Scene::from_toml(text, "x.toml", Path::new(".")));
    assert!(
        message.contains("fov_y_deg") && message.contains("0.1 to 170 degrees"),
        "{message}"
    );
}

#[test]
fn shipped_scenes_parse_with_the_documented_settings() {
    assert_eq!(
        Scene::builtin_names(),
        ["primitives", "chart", "colonnade", "walk"]
    );
    for name in Scene::builtin_names() {
        let scene = Scene::load(name).unwrap();
        assert!(scene.geometry.triangle_count() > 0, "{name}");
        assert!(scene.geometry.vertices.iter().all(|v| v
            .position_m
            .iter()
            .chain(&v.normal)
            .all(|c| c.is_finite())));
    }
    let primitives = Scene::load("primitives").unwrap();
    let state = primitives.at_time(0.0);
    assert!((state.focus_m - 7.5).abs() < 1e-12);
    assert_eq!(state.camera.fov_y_deg, 60.0);
    let chart = Scene::load("chart").unwrap();
    assert!((chart.at_time(0.0).focus_m - 6.0).abs() < 1e-12);
    let err = Scene::load("no-such-scene").unwrap_err();
    assert!(
        err.to_string().contains("primitives, chart, colonnade"),
        "{err}"
    );
}

#[test]
fn optotype_size_follows_the_five_arcminute_rule() {
    // Decimal acuity 1.0 (logMAR 0) at 6 m: 5 arcmin → 8.73 mm, the 6/6 letter.
    let h = letter_height_m(0.0, 6.0);
    assert!((h - 0.008_727).abs() < 1e-6, "{h}");
    // logMAR 1.0 is ten times larger (to first order in the angle).
    let h10 = letter_height_m(1.0, 6.0);
    assert!((h10 / h - 10.0).abs() < 1e-3, "{}", h10 / h);
}

fn animated_scene() -> Scene {
    let text = r#"
focus_m = 5.0

[camera]
position = [0.0, 1.0, 0.0]
yaw_deg = 170.0

[[object]]
kind = "cube"

[[keyframe]]
time_s = 0.0
focus_m = 4.0
pupil_mm = 3.0
camera = { position = [0.0, 1.0, 0.0], yaw_deg = 170.0 }

[[keyframe]]
time_s = 1.0
focus_m = 0.5
pupil_mm = 5.0
camera = { position = [1.0, 1.5, -2.0], yaw_deg = -170.0 }

[[keyframe]]
time_s = 3.0
focus_dpt = 0.0
pupil_mm = 4.0
camera = { position = [3.0, 1.0, -2.5], yaw_deg = -150.0, pitch_deg = 10.0 }
"#;
    Scene::from_toml(text, "animated", Path::new(".")).unwrap()
}

#[test]
fn animation_hits_keyframes_exactly() {
    let scene = animated_scene();
    assert_eq!(scene.duration_s(), 3.0);
    let keys = [
        (0.0, [0.0, 1.0, 0.0], 0.25, 3.0, 170.0),
        (1.0, [1.0, 1.5, -2.0], 2.0, 5.0, 190.0),
        (3.0, [3.0, 1.0, -2.5], 0.0, 4.0, 210.0),
    ];
    for (t, position, dpt, pupil, yaw) in keys {
        let s = scene.at_time(t);
        assert_eq!(s.camera.position_m, position, "t = {t}");
        assert!(
            (s.focus_dpt() - dpt).abs() < 1e-12,
            "t = {t}: {}",
            s.focus_dpt()
        );
        assert_eq!(s.pupil_mm, Some(pupil));
        // Yaw is unwrapped: 170 → -170 turns through 180, not back through 0.
        assert!(
            (s.camera.yaw_deg - yaw).abs() < 1e-9,
            "t = {t}: {}",
            s.camera.yaw_deg
        );
    }
    assert!(scene.at_time(3.0).focus_m.is_infinite());
    // Before the first and after the last key the values hold.
    assert_eq!(scene.at_time(-1.0).camera.position_m, [0.0, 1.0, 0.0]);
    assert_eq!(scene.at_time(10.0).camera.position_m, [3.0, 1.0, -2.5]);
    // Half-way between 170° and 190° the camera looks along +Z (yaw 180°), not -Z.
    let mid = scene.at_time(0.5).camera.forward();
    assert!(mid[2] > 0.99, "{mid:?}");
}

#[test]
fn animation_is_smooth_and_does_not_overshoot() {
    let scene = animated_scene();
    let x = |t: f64| scene.at_time(t).camera.position_m[0];
    let dpt = |t: f64| scene.at_time(t).focus_dpt();
    let h = 1e-5;
    for f in [&x as &dyn Fn(f64) -> f64, &dpt] {
        // C1 at the interior key: one-sided slopes agree.
        let left = (f(1.0) - f(1.0 - h)) / h;
        let right = (f(1.0 + h) - f(1.0)) / h;
        assert!(
            (left - right).abs() < 1e-3 * (1.0 + left.abs()),
            "{left} vs {right}"
        );
        // Continuous everywhere: no jumps on a fine grid.
        let mut previous = f(0.0);
        for i in 1..=3000 {
            let v = f(i as f64 * 1e-3);
            assert!((v - previous).abs() < 0.01, "jump at {}", i as f64 * 1e-3);
            previous = v;
        }
    }
    // Monotone data stay within their keys (x rises 0 → 1 → 3).
    for i in 0..=300 {
        let t = i as f64 * 0.01;
        let v = x(t);
        assert!((-1e-12..=3.0 + 1e-12).contains(&v), "x({t}) = {v}");
        if t <= 1.0 {
            assert!(v <= 1.0 + 1e-12, "x({t}) = {v} overshoots the key");
        }
    }
    // Focus 0.25 → 2 → 0 dpt: the turn at 1 s is a maximum, never exceeded.
    for i in 0..=300 {
        let d = dpt(i as f64 * 0.01);
        assert!((0.0..=2.0 + 1e-12).contains(&d), "{d}");
    }
}

#[test]
fn track_is_exact_at_keys_and_eases_at_the_ends() {
    let track = Track::new(&[(0.0, 1.0), (2.0, 3.0), (3.0, -1.0), (5.0, 0.0)]);
    for (t, v) in [(0.0, 1.0), (2.0, 3.0), (3.0, -1.0), (5.0, 0.0)] {
        assert_eq!(track.at(t), Some(v));
    }
    // Zero slope at the first key: eases in.
    let slope = (track.at(1e-6).unwrap() - 1.0) / 1e-6;
    assert!(slope.abs() < 1e-3, "{slope}");
    assert_eq!(Track::new(&[]).at(1.0), None);
    assert_eq!(Track::new(&[(1.0, 4.0)]).at(0.0), Some(4.0));
}

#[test]
fn still_scene_keeps_base_values() {
    let scene = Scene::load("colonnade").unwrap();
    let a = scene.at_time(0.0);
    let b = scene.at_time(12.0);
    assert_eq!(a.camera, b.camera);
    assert_eq!(a.focus_m, 2.0);
    assert_eq!(scene.duration_s(), 0.0);
}
