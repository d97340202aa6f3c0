//! `ocular render` on files shaped like Blender's (issue 19's eight defects, issue 20's
//! non-finite colour and exposure), end to end on lavapipe with 16×16 frames.

use crate::common;
use crate::common::{json_ok, module_cache, ocular, p, temp_dir};

use std::path::Path;
use std::process::Output;

use common::blender::{
    combined, cycles_layer, depth_values, plane, uniform_rgb, write_single_part,
};

const SIZE: (usize, usize) = (16, 16);
const N: usize = SIZE.0 * SIZE.1;

/// `ocular render` with the shared cache, a 4 mm pupil unless `args` sets the pupil, and `out`.
fn render(args: &[&str], out: &Path) -> Output {
    let mut c = ocular();
    c.arg("render").args(args);
    if !args
        .iter()
        .any(|a| a.starts_with("--pupil") || a.starts_with("--luminance"))
    {
        c.args(["--pupil-mm", "4"]);
    }
    c.arg("--cache").arg(module_cache()).arg("-o").arg(out);
    c.output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit 2, one `error:` line containing every `want`, and no output file.
fn refused(o: &Output, out: &Path, want: &[&str]) {
    let text = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{text}");
    assert!(
        text.starts_with("error:") && text.trim().lines().count() == 1,
        "{text}"
    );
    for w in want {
        assert!(text.contains(w), "{w:?} not in {text}");
    }
    assert!(!out.exists(), "an output was written");
}

#[test]
fn a_blender_multilayer_file_renders_with_its_combined_colour_and_depth() {
    let dir = temp_dir("blender");
    let cycles = dir.join("cycles.exr");
    write_single_part(&cycles, SIZE, cycles_layer("ViewLayer", SIZE, 1.0, 2.0));
    let out = dir.join("out.exr");

    // Defect 5: no silent 60° field of view.
    let o = render(&["--color", p(&cycles), "--eye", "navarro"], &out);
    refused(&o, &out, &["--fov-y", "vertical"]);

    // Defects 1 and 2: one file as colour and depth; the Combined pass and Depth.Z.
    // Defect 3: --focus-at on the background pixel (0, 0) focuses at infinity.
    let o = render(
        &[
            "--color",
            p(&cycles),
            "--fov-y",
            "30",
            "--eye",
            "navarro",
            "--focus-at",
            "0,0",
            "--json",
        ],
        &out,
    );
    let s = json_ok(&o);
    assert!(
        s["input"].as_str().unwrap().contains("ViewLayer.Combined"),
        "{s}"
    );
    assert!(
        s["depth"].as_str().unwrap().contains("ViewLayer.Depth.Z"),
        "{s}"
    );
    assert_eq!(s["focus_d"], 0.0);
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
    let image = ocular::image_io::read_exr_rgba(&out).unwrap();
    assert_eq!((image.width, image.height), (16, 16));
    assert!(image.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));

    // --focus-at on a real pixel uses its Depth.Z (2 + 0.25·row), not the denoising depth.
    let o = render(
        &[
            "--color",
            p(&cycles),
            "--fov-y",
            "30",
            "--eye",
            "navarro",
            "--focus-at",
            "3,4",
            "--json",
        ],
        &out,
    );
    let s = json_ok(&o);
    // Vergence along the pixel's ray: 3 m of view-axis depth at pixel (3, 4) of a 16-px-high,
    // 30° frame lies 3·√(1 + (u² + v²)/f²) m away (u, v from the image centre, f the focal
    // length in pixels).
    let f = 8.0 / 15f64.to_radians().tan();
    let (u, v) = (3.5 - 8.0, 4.5 - 8.0);
    let want = 1.0 / (3.0 * (1.0 + (u * u + v * v) / (f * f)).sqrt());
    assert!((s["focus_d"].as_f64().unwrap() - want).abs() < 1e-6, "{s}");

    // With the compositor's layer too: refused, listing both, until one is chosen.
    let both = dir.join("composite.exr");
    let mut planes = cycles_layer("ViewLayer", SIZE, 1.0, 2.0);
    planes.extend(combined("Composite", SIZE, 2.0));
    write_single_part(&both, SIZE, planes);
    std::fs::remove_file(&out).unwrap();
    let o = render(&["--color", p(&both), "--fov-y", "30"], &out);
    refused(
        &o,
        &out,
        &["ViewLayer.Combined", "Composite.Combined", "--color-layer"],
    );
    let o = render(
        &[
            "--color",
            p(&both),
            "--fov-y",
            "30",
            "--color-layer",
            "Composite",
            "--eye",
            "navarro",
            "--focus-m",
            "2",
            "--json",
        ],
        &out,
    );
    let s = json_ok(&o);
    assert!(s["input"].as_str().unwrap().contains("Composite.Combined"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn far_focus_background_and_near_pixels_render_instead_of_failing() {
    let dir = temp_dir("depth");
    let colour = dir.join("c.exr");
    write_single_part(&colour, SIZE, uniform_rgb(N, [1.0; 3]));
    // Sky (Cycles' 1e10) over the whole top half and the centre; one pixel at 1 cm.
    let mut z = depth_values(SIZE, 2.0, 1e10);
    for v in z.iter_mut().take(N / 2 + SIZE.0) {
        *v = 1e10;
    }
    z[N - 1] = 0.01;
    let depth = dir.join("d.exr");
    write_single_part(&depth, SIZE, vec![plane("ViewLayer.Depth.Z", z)]);
    let out = dir.join("out.png");
    let base = ["--color", p(&colour), "--depth", p(&depth), "--fov-y", "40"];
    // Defect 3: a large finite focus distance, a tiny vergence, and the default focus over
    // the sky all mean infinity, for an eye (healthy) that can focus there.
    for extra in [
        &["--focus-m", "1e10"][..],
        &["--focus-d", "0.00000001"][..],
        &[][..],
    ] {
        let mut args = base.to_vec();
        args.extend_from_slice(&["--eye", "healthy", "--json"]);
        args.extend_from_slice(extra);
        let o = render(&args, &out);
        let s = json_ok(&o);
        assert_eq!(s["focus_d"], 0.0, "{extra:?}");
        // Defect 4: the 1 cm pixel is clamped with one warning that counts it.
        let text = stderr(&o);
        assert_eq!(text.matches("warning:").count(), 1, "{extra:?}: {text}");
        assert!(
            text.contains("1 pixel(s) nearer than 0.0200 m") && text.contains("d.exr"),
            "{text}"
        );
        assert_eq!(s["warnings"].as_array().unwrap().len(), 1);
        assert_eq!(s["depth_report"]["clamped_near_px"], 1);
        assert_eq!(s["depth_report"]["background_px"], N / 2 + SIZE.0);
    }

    // Defect 8: a constant depth map (Blender's Z = 1 trap) is accepted with a warning.
    let flat = dir.join("flat.exr");
    write_single_part(&flat, SIZE, vec![plane("Z", vec![1.0; N])]);
    let o = render(
        &[
            "--color",
            p(&colour),
            "--depth",
            p(&flat),
            "--fov-y",
            "40",
            "--focus-m",
            "1",
        ],
        &out,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("1 m at every pixel"), "{}", stderr(&o));

    // --depth-scale: centimetres.
    let cm = dir.join("cm.exr");
    write_single_part(&cm, SIZE, vec![plane("Z", vec![250.0; N])]);
    let o = render(
        &[
            "--color",
            p(&colour),
            "--depth",
            p(&cm),
            "--fov-y",
            "40",
            "--depth-scale",
            "0.01",
            "--json",
        ],
        &out,
    );
    let s = json_ok(&o);
    // The default focus is the centre pixel (8, 8), half a pixel off the axis of a 40° frame.
    let f = 8.0 / 20f64.to_radians().tan();
    let want = 0.4 / (1.0 + 0.5 / (f * f)).sqrt();
    assert!((s["focus_d"].as_f64().unwrap() - want).abs() < 1e-6, "{s}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn focus_beyond_the_far_point_is_reported_where_the_eye_focuses() {
    let dir = temp_dir("far-point");
    let colour = dir.join("c.exr");
    let mut planes = uniform_rgb(N, [1.0; 3]);
    planes.push(plane("Z", depth_values(SIZE, 5.0, 1e10)));
    write_single_part(&colour, SIZE, planes);
    let out = dir.join("out.png");
    // The myopia preset cannot relax to 5 m: its far point, by an independent paraxial
    // trace at the accommodation wavelength, is at −(paraxial refraction) dioptres.
    let eye = ocular::eye::preset("myopia").unwrap().eye;
    let sys = eye.system().unwrap();
    let far_point_d = -ocular::eye::paraxial(&sys, 549.0, 0.0).refraction_d;
    assert!(far_point_d > 5.0, "{far_point_d}");
    let args = [
        "--color",
        p(&colour),
        "--fov-y",
        "40",
        "--eye",
        "myopia",
        "--focus-m",
        "5",
    ];
    let mut with_json = args.to_vec();
    with_json.push("--json");
    let s = json_ok(&render(&with_json, &out));
    assert!((s["focus_d"].as_f64().unwrap() - 0.2).abs() < 1e-9);
    assert_eq!(s["focus_clamped"], true);
    let actual = s["focus_actual_d"].as_f64().unwrap();
    // A 4 mm pupil's spherical aberration moves the best focus a little from paraxial.
    assert!(
        (actual - far_point_d).abs() < 0.15,
        "{actual} vs {far_point_d}"
    );
    let o = render(&args, &out);
    let line = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        line.contains(&format!("focused at {:.3} m", 1.0 / actual))
            && line.contains("far point")
            && line.contains("asked 5.000 m"),
        "{line}"
    );
    // An eye that can focus there is not clamped.
    let mut healthy = with_json.clone();
    healthy[5] = "healthy";
    healthy[7] = "1";
    let s = json_ok(&render(&healthy, &out));
    assert_eq!(s["focus_clamped"], false);
    assert_eq!(s["focus_actual_d"], s["focus_d"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pictures_and_bad_values_at_the_boundary() {
    let dir = temp_dir("pictures");
    let depth = dir.join("d.exr");
    write_single_part(
        &depth,
        SIZE,
        vec![plane("Z", depth_values(SIZE, 2.0, 1e10))],
    );
    let out = dir.join("out.exr");
    // Defect 6: PNG colour.
    let png = dir.join("c.png");
    image::RgbImage::from_pixel(16, 16, image::Rgb([255, 255, 255]))
        .save(&png)
        .unwrap();
    let s = json_ok(&render(
        &[
            "--color",
            p(&png),
            "--depth",
            p(&depth),
            "--fov-y",
            "40",
            "--eye",
            "navarro",
            "--focus-m",
            "2",
            "--white-cdm2",
            "150",
            "--json",
        ],
        &out,
    ));
    assert!(
        s["input"]
            .as_str()
            .unwrap()
            .contains("sRGB, white 150 cd/m²"),
        "{s}"
    );
    // White 150 cd/m² through a normalised PSF: interior pixels stay at 150.
    let image = ocular::image_io::read_exr_rgba(&out).unwrap();
    let centre = image.pixels[8 * 16 + 8];
    assert!((centre[1] - 150.0).abs() < 1.5, "{centre:?}");
    std::fs::remove_file(&out).unwrap();

    // Issue 20, defect 1: one NaN pixel is refused (count, first pixel), or repaired on request.
    let nan = dir.join("nan.exr");
    let mut g = vec![0.5; N];
    g[16 * 2 + 7] = f32::NAN;
    write_single_part(
        &nan,
        SIZE,
        vec![
            plane("R", vec![0.5; N]),
            plane("G", g),
            plane("B", vec![0.5; N]),
        ],
    );
    let base = ["--color", p(&nan), "--depth", p(&depth), "--fov-y", "40"];
    refused(
        &render(&base, &out),
        &out,
        &["nan.exr", "1 pixel(s)", "(7, 2)"],
    );
    let mut repaired = base.to_vec();
    repaired.extend_from_slice(&["--repair-nonfinite", "--eye", "navarro", "--focus-m", "2"]);
    let o = render(&repaired, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    let image = ocular::image_io::read_exr_rgba(&out).unwrap();
    assert!(image.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));
    std::fs::remove_file(&out).unwrap();

    // Issue 20, defect 8: exposure must be finite.
    for ev in ["--exposure=nan", "--exposure=inf", "--exposure=-inf"] {
        let png_out = dir.join("x.png");
        let o = render(&["--size", "32x18", ev], &png_out);
        refused(&o, &png_out, &["--exposure"]);
    }
    // A focus nearer than the kernels reach names the option, in metres.
    let png_out = dir.join("x.png");
    refused(
        &render(&["--size", "32x18", "--focus-m", "0.001"], &png_out),
        &png_out,
        &["--focus-m", "0.0010 m"],
    );
    // File options with a scene are refused, not ignored.
    let png_out = dir.join("x.png");
    refused(
        &render(&["--scene", "chart", "--fov-y", "30"], &png_out),
        &png_out,
        &["--fov-y", "--color"],
    );
    // The depth scale and white luminance are range-checked with their names.
    let mut bad_scale = base.to_vec();
    bad_scale.extend_from_slice(&["--depth-scale", "0"]);
    refused(&render(&bad_scale, &out), &out, &["--depth-scale"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
