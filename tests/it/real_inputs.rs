//! Reading what other tools write (issue 19, defects 1, 2, 4, 6 and 8; issue 20, defects 1 and
//! 3): synthetic files with Blender's exact channel names, read through `ocular::inputs`.
//! Every file's colour and depth planes carry distinct values, so that taking the wrong plane
//! fails the assertions instead of passing by coincidence.

use crate::common;
use crate::common::temp_dir;

use common::blender::{
    combined, cycles_layer, depth_values, half_plane, options, plane, uniform_rgb,
    write_multi_part, write_single_part, write_views,
};
use ocular::inputs::{self, FileInputOptions};

const SIZE: (usize, usize) = (16, 16);

fn error_of(options: &FileInputOptions) -> (i32, String) {
    let e = inputs::load(options).unwrap_err();
    (e.exit_code(), e.to_string())
}

/// The depth the test files hold at pixel `i` (row-dependent), before the policy.
fn expected_depth(i: usize, near: f32) -> f32 {
    near + 0.25 * (i / SIZE.0) as f32
}

#[test]
fn blender_multilayer_files_give_combined_colour_and_depth_z() {
    let dir = temp_dir("multilayer");
    // Defect 1: Cycles' F12 multilayer EXR, one file as colour and depth.
    let cycles = dir.join("cycles.exr");
    write_single_part(&cycles, SIZE, cycles_layer("ViewLayer", SIZE, 10.0, 2.0));
    let got = inputs::load(&options(&cycles)).unwrap();
    assert_eq!(got.color.pixels[3], [13.0, 20.0, 30.0, 1.0]);
    assert!(got.color_source.contains("ViewLayer.Combined"));
    assert!(
        got.depth_source.contains("ViewLayer.Depth.Z"),
        "{}",
        got.depth_source
    );
    // Defect 2: the view-axis Depth.Z wins over Denoising Depth (×1.1) and Mist (0.5).
    assert_eq!(got.depth_m[0], f32::INFINITY, "1e10 is background");
    for i in [1, 17, 255] {
        assert_eq!(got.depth_m[i], expected_depth(i, 2.0), "pixel {i}");
    }
    assert_eq!(got.depth_report.background_px, 1);
    assert!(got.warnings.is_empty(), "{:?}", got.warnings);

    // Eevee: half floats with 65504 as background.
    let eevee = dir.join("eevee.exr");
    let mut planes: Vec<_> = combined("ViewLayer", SIZE, 0.5)
        .into_iter()
        .map(|p| half_plane(&p.name, p.values))
        .collect();
    planes.push(half_plane(
        "ViewLayer.Depth.Z",
        depth_values(SIZE, 3.0, 65504.0),
    ));
    write_single_part(&eevee, SIZE, planes);
    let got = inputs::load(&options(&eevee)).unwrap();
    assert_eq!(got.color.pixels[2], [2.5, 1.0, 1.5, 1.0]);
    assert_eq!(
        got.depth_m[0],
        f32::INFINITY,
        "65504 in a half channel is background"
    );
    assert_eq!(got.depth_m[16], 3.25);

    // File Output node, multilayer, slots Image and Depth: Image.{R,G,B,A}, Depth.V.
    let node = dir.join("node.exr");
    let n = SIZE.0 * SIZE.1;
    write_single_part(
        &node,
        SIZE,
        vec![
            plane("Image.R", vec![7.0; n]),
            plane("Image.G", vec![8.0; n]),
            plane("Image.B", vec![9.0; n]),
            plane("Image.A", vec![1.0; n]),
            plane("Depth.V", depth_values(SIZE, 4.0, 1e10)),
        ],
    );
    let got = inputs::load(&options(&node)).unwrap();
    assert_eq!(got.color.pixels[5], [7.0, 8.0, 9.0, 1.0]);
    assert!(got.depth_source.contains("Depth.V"));
    assert_eq!(
        got.depth_m[16], 4.25,
        "Image.R (7) must not be read as depth"
    );

    // A luminance-only (Y) EXR as colour, with a separate depth file.
    let grey = dir.join("y.exr");
    write_single_part(&grey, SIZE, vec![plane("Y", vec![0.25; n])]);
    let depth = dir.join("z.exr");
    write_single_part(
        &depth,
        SIZE,
        vec![plane("Z", depth_values(SIZE, 1.0, 1e10))],
    );
    let mut o = options(&grey);
    o.depth = Some(depth.clone());
    let got = inputs::load(&o).unwrap();
    assert_eq!(got.color.pixels[7], [0.25, 0.25, 0.25, 1.0]);
    assert_eq!(got.depth_m[17], 1.25);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn several_layers_need_a_choice_and_the_choice_picks_its_own_depth() {
    let dir = temp_dir("layers");
    // The compositor adds Composite.Combined; a second view layer adds Background.*.
    let file = dir.join("two.exr");
    let mut planes = cycles_layer("ViewLayer", SIZE, 10.0, 2.0);
    planes.extend(combined("Composite", SIZE, 20.0));
    planes.extend(combined("Background", SIZE, 30.0));
    planes.push(plane("Background.Depth.Z", depth_values(SIZE, 6.0, 1e10)));
    write_single_part(&file, SIZE, planes);
    let (code, text) = error_of(&options(&file));
    assert_eq!(code, 2);
    for want in [
        "ViewLayer.Combined",
        "Composite.Combined",
        "Background.Combined",
        "--color-layer",
    ] {
        assert!(text.contains(want), "{want}: {text}");
    }
    assert_eq!(text.lines().count(), 1);

    let mut o = options(&file);
    o.color_layer = Some("Background".into());
    let got = inputs::load(&o).unwrap();
    assert_eq!(got.color.pixels[0][1], 60.0);
    assert_eq!(got.depth_m[16], 6.25, "depth follows the chosen layer");

    o.color_layer = Some("Composite.Combined".into());
    let (code, text) = error_of(&o);
    assert_eq!(code, 2);
    assert!(
        text.contains("ViewLayer.Depth.Z")
            && text.contains("Background.Depth.Z")
            && text.contains("--depth-channel"),
        "{text}"
    );
    o.depth_channel = Some("ViewLayer.Depth.Z".into());
    let got = inputs::load(&o).unwrap();
    assert_eq!(got.color.pixels[0][1], 40.0);
    assert_eq!(got.depth_m[16], 2.25);

    o.color_layer = Some("NoSuchLayer".into());
    let (_, text) = error_of(&o);
    assert!(
        text.contains("NoSuchLayer") && text.contains("ViewLayer.Combined"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stereo_views_need_a_choice_and_depth_follows_the_view() {
    let dir = temp_dir("views");
    let path = dir.join("stereo.exr");
    let view = |base: f32, near: f32| {
        let mut planes: Vec<_> = combined("ViewLayer", SIZE, base);
        planes.push(plane("ViewLayer.Depth.Z", depth_values(SIZE, near, 1e10)));
        planes
    };
    write_views(
        &path,
        SIZE,
        vec![
            ("left", "left", view(1.0, 2.0)),
            ("right", "right", view(5.0, 3.0)),
        ],
    );
    let (code, text) = error_of(&options(&path));
    assert_eq!(code, 2);
    assert!(
        text.contains("left.ViewLayer.Combined")
            && text.contains("right.ViewLayer.Combined")
            && text.contains("--color-layer"),
        "{text}"
    );
    let mut o = options(&path);
    o.color_layer = Some("right".into());
    let got = inputs::load(&o).unwrap();
    assert_eq!(got.color.pixels[0][1], 10.0);
    assert_eq!(got.depth_m[16], 3.25, "the right view's depth");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn depth_is_never_taken_from_the_wrong_pass_or_part() {
    let dir = temp_dir("depth-pass");
    let n = SIZE.0 * SIZE.1;
    // Multi-part: colour in the first part (its R would have been read as depth), depth in the
    // second.
    let parts = dir.join("parts.exr");
    write_multi_part(
        &parts,
        SIZE,
        vec![
            ("ViewLayer.Combined", uniform_rgb(n, [0.7, 0.8, 0.9])),
            (
                "ViewLayer.Depth",
                vec![plane("Z", depth_values(SIZE, 5.0, 1e10))],
            ),
        ],
    );
    let got = inputs::load(&options(&parts)).unwrap();
    assert_eq!(got.color.pixels[9], [0.7, 0.8, 0.9, 1.0]);
    assert!(
        got.depth_source.contains("ViewLayer.Depth.Z"),
        "{}",
        got.depth_source
    );
    assert_eq!(got.depth_m[33], 5.5);

    // Mist-only and Normal-only files are not depth: refused, listing what is there.
    let colour = dir.join("rgb.exr");
    write_single_part(&colour, SIZE, uniform_rgb(n, [1.0; 3]));
    for (name, planes) in [
        ("mist", vec![plane("ViewLayer.Mist.Z", vec![0.5; n])]),
        (
            "normal",
            vec![
                plane("ViewLayer.Normal.X", vec![0.1; n]),
                plane("ViewLayer.Normal.Y", vec![0.2; n]),
                plane("ViewLayer.Normal.Z", vec![0.9; n]),
            ],
        ),
        (
            "denoising",
            vec![plane("ViewLayer.Denoising Depth.Z", vec![3.0; n])],
        ),
    ] {
        let path = dir.join(format!("{name}.exr"));
        write_single_part(&path, SIZE, planes);
        let mut o = options(&colour);
        o.depth = Some(path.clone());
        let (code, text) = error_of(&o);
        assert_eq!(code, 2, "{name}");
        assert!(
            text.contains(&path.display().to_string())
                && text.contains("ViewLayer.")
                && text.contains("--depth-channel"),
            "{name}: {text}"
        );
        // …unless asked for explicitly.
        if name == "mist" {
            o.depth_channel = Some("ViewLayer.Mist.Z".into());
            assert_eq!(inputs::load(&o).unwrap().depth_m[0], 0.5);
        }
    }
    // The Blender "Z buffer" EXR: R, G, B, A, Z in one part; here the Z = 1 trap.
    let zbuf = dir.join("zbuf.exr");
    let mut planes = uniform_rgb(n, [0.2, 0.3, 0.4]);
    planes.push(plane("A", vec![1.0; n]));
    planes.push(plane("Z", vec![1.0; n]));
    write_single_part(&zbuf, SIZE, planes);
    let got = inputs::load(&options(&zbuf)).unwrap();
    assert_eq!(got.depth_report.constant_m, Some(1.0));
    assert!(
        got.warnings
            .iter()
            .any(|w| w.contains("zbuf.exr") && w.contains("every pixel")),
        "{:?}",
        got.warnings
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_depth_policy_counts_background_invalid_and_near_pixels() {
    use ocular::inputs::apply;
    let raw = [
        1e10,
        f32::INFINITY,
        0.0,
        65504.0,
        f32::NAN,
        -2.0,
        f32::NEG_INFINITY,
        0.01,
        0.5,
        2.0,
    ];
    let (out, report) = apply(&raw, 5, false, 1.0);
    assert_eq!(report.background_px, 3, "1e10, +inf, 0");
    assert_eq!(
        out[3], 65504.0,
        "65504 is only background in half-float files"
    );
    assert_eq!(report.invalid_px, 3);
    assert_eq!(report.first_invalid, Some((4, 0)));
    assert!(out[..3]
        .iter()
        .chain(&out[4..7])
        .all(|&d| d == f32::INFINITY));
    assert_eq!(report.clamped_near_px, 1);
    // the default object axis's nearest sample (1/16 D steps from 0 D): 50 D
    assert!((out[7] - 1.0 / 50.0).abs() < 1e-8, "{}", out[7]);
    assert_eq!(report.constant_m, None);
    let warnings = report.warnings();
    assert!(warnings
        .iter()
        .any(|w| w.contains("3 pixel(s)") && w.contains("(4, 0)")));
    assert!(warnings
        .iter()
        .any(|w| w.starts_with("1 pixel(s) nearer than 0.0200 m")));

    // Half floats: 65504 is the background marker. --depth-scale converts units to metres
    // (centimetres here) after the background test on raw values.
    let (out, report) = apply(&[65504.0, 150.0, 250.0], 3, true, 0.01);
    assert_eq!(report.background_px, 1);
    assert_eq!(out, vec![f32::INFINITY, 1.5, 2.5]);
    let (_, report) = apply(&[1.0, 1.0, 1e10, 1.0], 2, false, 1.0);
    assert_eq!(
        report.constant_m,
        Some(1.0),
        "background does not break constancy"
    );
}

#[test]
fn non_finite_colour_is_refused_or_repaired_on_request() {
    let dir = temp_dir("nan");
    let n = SIZE.0 * SIZE.1;
    let mut r = vec![0.5; n];
    r[16 * 3 + 5] = f32::NAN;
    r[16 * 9 + 1] = f32::INFINITY;
    let path = dir.join("nan.exr");
    write_single_part(
        &path,
        SIZE,
        vec![
            plane("R", r),
            plane("G", vec![0.5; n]),
            plane("B", vec![0.5; n]),
            plane("Z", vec![2.0; n]),
        ],
    );
    let (code, text) = error_of(&options(&path));
    assert_eq!(code, 2);
    assert!(
        text.contains("nan.exr") && text.contains("2 pixel(s)") && text.contains("(5, 3)"),
        "{text}"
    );
    let mut o = options(&path);
    o.repair_nonfinite = true;
    let got = inputs::load(&o).unwrap();
    assert_eq!(got.color.pixels[16 * 3 + 5], [0.0, 0.5, 0.5, 1.0]);
    assert!(got
        .color
        .pixels
        .iter()
        .all(|p| p.iter().all(|v| v.is_finite())));
    assert!(got
        .warnings
        .iter()
        .any(|w| w.contains("--repair-nonfinite")));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pictures_are_decoded_from_srgb_and_scaled_to_white() {
    let dir = temp_dir("pictures");
    let depth = dir.join("d.exr");
    write_single_part(&depth, (4, 2), vec![plane("Z", vec![3.0; 8])]);
    // sRGB 8-bit codes and their linear values from the IEC 61966-2-1 table (independent of
    // the decoder): 0 → 0, 128 → 0.2158605, 255 → 1.
    let codes: [u8; 8] = [0, 128, 255, 128, 0, 255, 64, 200];
    let linear_128 = 0.215_860_5f32;
    let rgb: Vec<u8> = codes.iter().flat_map(|&c| [c, c, c]).collect();
    let png = dir.join("c.png");
    image::RgbImage::from_raw(4, 2, rgb.clone())
        .unwrap()
        .save(&png)
        .unwrap();
    let tif = dir.join("c.tif");
    image::RgbImage::from_raw(4, 2, rgb)
        .unwrap()
        .save(&tif)
        .unwrap();
    for path in [&png, &tif] {
        let mut o = options(path);
        o.depth = Some(depth.clone());
        let got = inputs::load(&o).unwrap();
        assert_eq!(got.color.pixels[0], [0.0, 0.0, 0.0, 1.0]);
        assert!((got.color.pixels[1][0] - 80.0 * linear_128).abs() < 1e-3);
        assert!(
            (got.color.pixels[2][1] - 80.0).abs() < 1e-4,
            "white is 80 cd/m²"
        );
        o.white_cdm2 = Some(250.0);
        let got = inputs::load(&o).unwrap();
        assert!((got.color.pixels[3][2] - 250.0 * linear_128).abs() < 1e-3);
    }
    // JPEG is lossy: a flat mid-grey stays within a code value or two.
    let jpg = dir.join("c.jpg");
    image::RgbImage::from_pixel(16, 16, image::Rgb([128, 128, 128]))
        .save(&jpg)
        .unwrap();
    let mut o = options(&jpg);
    let jdepth = dir.join("dj.exr");
    write_single_part(&jdepth, (16, 16), vec![plane("Z", vec![3.0; 256])]);
    o.depth = Some(jdepth);
    let got = inputs::load(&o).unwrap();
    let v = got.color.pixels[40][0] / 80.0;
    assert!((v - linear_128).abs() < 0.01, "{v}");

    // A picture needs a depth EXR; --white-cdm2 is for pictures only.
    let (code, text) = error_of(&options(&png));
    assert_eq!(code, 2);
    assert!(
        text.contains("--depth") || text.contains("depth must be an EXR"),
        "{text}"
    );
    // EXR colour is cd/m² unless --white-cdm2 says what 1.0 is (Blender's scene-linear
    // values are relative).
    let exr = dir.join("c.exr");
    let mut planes = uniform_rgb(8, [0.5, 0.25, 1.0]);
    planes.push(plane("Z", vec![3.0; 8]));
    write_single_part(&exr, (4, 2), planes);
    let mut o = options(&exr);
    assert_eq!(
        inputs::load(&o).unwrap().color.pixels[0],
        [0.5, 0.25, 1.0, 1.0]
    );
    o.white_cdm2 = Some(100.0);
    assert_eq!(
        inputs::load(&o).unwrap().color.pixels[0],
        [50.0, 25.0, 100.0, 1.0]
    );
    o.white_cdm2 = Some(-1.0);
    assert!(error_of(&o).1.contains("--white-cdm2"));
    let mut o = options(&dir.join("c.bmp"));
    o.depth = Some(depth.clone());
    assert!(error_of(&o).1.contains(".png"));
    std::fs::remove_dir_all(&dir).unwrap();
}
