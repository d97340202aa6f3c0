//! `ocular raster` end to end: outputs on success, one clear line and exit code 2 on bad input.

use crate::common::{data, ocular, ok, temp_dir};

#[test]
fn raster_writes_colour_depth_and_preview() {
    let dir = temp_dir("ok");
    let (colour, depth, png) = (dir.join("c.exr"), dir.join("d.exr"), dir.join("p.png"));
    // From another folder, by name: the shipped scenes are built in.
    let out = ocular()
        .current_dir(&dir)
        .args(["raster", "--scene", "primitives", "--size", "160x90", "-o"])
        .arg(&colour)
        .arg("--depth-out")
        .arg(&depth)
        .arg("--png")
        .arg(&png)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("160×90") && stdout.contains("triangles"),
        "{stdout}"
    );
    let c = ocular::image_io::read_exr_rgba(&colour).unwrap();
    let d = ocular::image_io::read_exr_depth(&depth).unwrap();
    assert_eq!((c.width, c.height, d.width, d.height), (160, 90, 160, 90));
    assert!(c.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));
    assert!(d.pixels.iter().all(|&v| v > 0.0 && v.is_finite()));
    assert_eq!(image::open(&png).unwrap().to_rgb8().dimensions(), (160, 90));
    std::fs::remove_dir_all(&dir).unwrap();
}

fn fails_with(args: &[&str], expected: &[&str]) {
    let dir = temp_dir("fail");
    let out = ocular()
        .args(args)
        .arg("-o")
        .arg(dir.join("never.exr"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("error:"), "{stderr}");
    for e in expected {
        assert!(stderr.contains(e), "{args:?}: expected {e:?} in {stderr}");
    }
    assert!(!dir.join("never.exr").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_scene_obj_or_texture_fails_with_file_line_and_exit_code_2() {
    let path = |n: &str| data(n).to_string_lossy().into_owned();
    fails_with(
        &["raster", "--scene", &path("bad_syntax.toml")],
        &["bad_syntax.toml", "line 5"],
    );
    fails_with(
        &["raster", "--scene", &path("bad_field.toml")],
        &["bad_field.toml", "line 7", "raduis"],
    );
    fails_with(
        &["raster", "--scene", &path("bad_obj_scene.toml")],
        &["bad_face.obj", "line 5"],
    );
    fails_with(
        &["raster", "--scene", &path("missing_obj_scene.toml")],
        &["no_such_model.obj", "not found"],
    );
    fails_with(
        &["raster", "--scene", &path("no_such_scene.toml")],
        &["no_such_scene.toml", "not found"],
    );
    fails_with(&["raster", "--scene", "nonesuch"], &["primitives"]);
    // Malformed options are clap's usage errors: exit code 2 as well.
    let out = ocular()
        .args([
            "raster",
            "--scene",
            "primitives",
            "--size",
            "0x5",
            "-o",
            "x.exr",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--size"));
}

#[test]
fn raster_help_explains_units() {
    let out = ocular().args(["raster", "--help"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "--scene",
        "--depth-out",
        "--png",
        "cd/m²",
        "metres",
        "colonnade",
    ] {
        assert!(text.contains(needle), "missing {needle} in\n{text}");
    }
}

#[test]
fn time_option_evaluates_keyframes() {
    let dir = temp_dir("time");
    let scene = dir.join("moving.toml");
    std::fs::write(
        &scene,
        r#"
[camera]
position = [0.0, 0.0, 0.0]
far_m = 50.0

[[object]]
kind = "plane"
size_m = 100.0
translate = [0.0, 0.0, -5.0]

[[keyframe]]
time_s = 0.0
camera = { position = [0.0, 0.0, 0.0] }

[[keyframe]]
time_s = 2.0
camera = { position = [0.0, 0.0, -3.0] }
"#,
    )
    .unwrap();
    for (time, expected) in [("0", 5.0f32), ("2", 2.0), ("9", 2.0)] {
        let depth = dir.join(format!("d{time}.exr"));
        let out = ocular()
            .args(["raster", "--size", "32x18", "--time", time, "--scene"])
            .arg(&scene)
            .arg("--depth-out")
            .arg(&depth)
            .output()
            .unwrap();
        ok(&out);
        let d = ocular::image_io::read_exr_depth(&depth).unwrap();
        assert!(
            d.pixels
                .iter()
                .all(|&v| (v - expected).abs() < 1e-4 * expected),
            "t = {time}: {:?}",
            &d.pixels[..4]
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
