//! The rasteriser on lavapipe: metric depth, angular size, shading calibration, the shipped
//! scenes, and the graphics-pipeline layer's own checks.

use crate::common;
use crate::common::scenes::{scene, square_scene};

use ocular::gpu::{
    BindingKind, DepthCompare, GpuError, GraphicsPipeline, Image, ImageUsage, TexelFormat,
    VertexAttribute, VertexFormat,
};
use ocular::image_io::luminance;
use ocular::render::Rasterizer;
use ocular::scene::Scene;

#[test]
fn plane_facing_the_camera_has_its_distance_as_depth_everywhere() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    for distance in [0.3, 3.0, 47.5] {
        let s = scene(&format!(
            r#"
[camera]
position = [0.4, -0.2, 1.0]
yaw_deg = 0.0
fov_y_deg = 60.0
far_m = 100.0

[[object]]
kind = "plane"
size_m = 500.0
translate = [0.0, 0.0, {}]
"#,
            1.0 - distance
        ));
        let frame = raster.render(&ctx, &s.at_time(0.0), 160, 90).unwrap();
        assert_eq!(frame.depth_m.len(), 160 * 90);
        let worst = frame
            .depth_m
            .iter()
            .map(|&d| ((f64::from(d) - distance) / distance).abs())
            .fold(0.0, f64::max);
        eprintln!("plane at {distance} m: worst relative depth error {worst:.1e}");
        assert!(worst < 1e-4, "distance {distance}: relative error {worst}");
    }
    drop(raster);
    common::finish(ctx);
}

#[test]
fn tilted_floor_depth_matches_the_ray_geometry() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    // Looking 45° down at a floor 1.5 m below: every pixel sees the floor.
    let s = scene(
        r#"
[camera]
position = [0.0, 0.0, 0.0]
yaw_deg = 30.0
pitch_deg = -45.0
fov_y_deg = 50.0
far_m = 100.0

[[object]]
kind = "plane"
size_m = 400.0
translate = [0.0, -1.5, 0.0]
rotate_deg = [-90.0, 0.0, 0.0]
"#,
    );
    let state = s.at_time(0.0);
    let (w, h) = (160u32, 90u32);
    let frame = raster.render(&ctx, &state, w, h).unwrap();
    let cam = state.camera;
    let f = glam::DVec3::from(cam.forward());
    let right = f.cross(glam::DVec3::Y).normalize();
    let up = right.cross(f);
    let tan_half = (cam.fov_y_deg.to_radians() / 2.0).tan();
    let aspect = f64::from(w) / f64::from(h);
    let mut worst = 0.0f64;
    for y in 0..h {
        for x in 0..w {
            let sx = (2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0) * tan_half * aspect;
            let sy = (1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h)) * tan_half;
            // Ray with unit component along the view direction: its parameter is the depth.
            let dir = f + right * sx + up * sy;
            let expected = -1.5 / dir.y;
            let got = f64::from(frame.depth_m[(y * w + x) as usize]);
            worst = worst.max(((got - expected) / expected).abs());
        }
    }
    eprintln!("tilted floor: worst relative depth error {worst:.1e}");
    assert!(worst < 1e-4, "relative error {worst}");
    drop(raster);
    common::finish(ctx);
}

#[test]
fn object_of_known_angular_size_covers_the_expected_pixels() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let (w, h) = (160u32, 90u32);
    let fov = 30.0f64;
    for (half, distance) in [(0.2, 2.0), (0.05, 0.9), (1.3, 17.0)] {
        let s = square_scene(half, distance, fov);
        let frame = raster.render(&ctx, &s.at_time(0.0), w, h).unwrap();
        // Side in pixels: focal length (pixels per unit tangent) times the tangent subtended.
        let focal_px = 0.5 * f64::from(h) / (fov.to_radians() / 2.0).tan();
        let side = focal_px * 2.0 * half / distance;
        let area = side * side;
        // Colour coverage: MSAA gives each pixel the fraction of its 4 samples inside, so the
        // sum is the area up to the 4-sample quantisation along the edges: at most 1/2 of a
        // pixel per edge pixel (4·(side + 1) of them), in practice far less.
        let coverage: f64 = frame
            .color
            .iter()
            .map(|c| f64::from(luminance([c[0], c[1], c[2]])) / 100.0)
            .sum();
        // Depth coverage: a pixel takes the square's depth when any sample is inside, so the
        // count lies between the pixels wholly inside and those touched: (side ∓ 2)² at worst.
        let covered = frame.depth_m.iter().filter(|&&d| d < 99.0).count() as f64;
        eprintln!(
            "square {side:.2} px: area {area:.1}, colour coverage {coverage:.1}, depth pixels {covered}"
        );
        assert!(
            (coverage - area).abs() <= 2.0 * (side + 1.0),
            "colour coverage {coverage} vs area {area}"
        );
        assert!(
            covered >= (side - 2.0).powi(2) && covered <= (side + 2.0).powi(2),
            "depth coverage {covered} vs area {area}"
        );
        // Every covered pixel carries the square's own depth, never a blend with the far
        // background.
        assert!(frame
            .depth_m
            .iter()
            .all(|&d| d == 100.0 || ((f64::from(d) - distance) / distance).abs() < 1e-4));
    }
    drop(raster);
    common::finish(ctx);
}

#[test]
fn optotype_height_in_pixels_follows_acuity_and_distance() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    // 90 pixels over 1.5° = 1 arcmin per pixel: logMAR 1.0 is 50 arcmin → 50 rows.
    let s = scene(
        r#"
[camera]
position = [0.0, 0.0, 0.0]
fov_y_deg = 1.5
far_m = 100.0

# As bright as the card, so that only the letter is dark.
[background]
luminance_cd_m2 = 143.2

[[light]]
kind = "ambient"
illuminance_lux = 500.0

[[object]]
kind = "optotype"
letter = "E"
logmar = 1.0
translate = [0.0, 0.0, -6.0]
"#,
    );
    let frame = raster.render(&ctx, &s.at_time(0.0), 160, 90).unwrap();
    let card_y = 0.9 * 500.0 / std::f32::consts::PI;
    let dark = |c: &[f32; 4]| luminance([c[0], c[1], c[2]]) < 0.5 * card_y;
    let rows = (0..90)
        .filter(|y| (0..160).any(|x| dark(&frame.color[y * 160 + x])))
        .count();
    let columns = (0..160)
        .filter(|&x| (0..90).any(|y| dark(&frame.color[y * 160 + x])))
        .count();
    eprintln!("E of logMAR 1.0 at 6 m: {rows} rows × {columns} columns at 1 arcmin/pixel");
    assert!((49..=51).contains(&rows), "{rows}");
    assert!((49..=51).contains(&columns), "{columns}");
    // The card spans columns 30..130; the letter sits in front of it by a hair.
    for y in 0..90 {
        for x in 35..125 {
            let d = f64::from(frame.depth_m[y * 160 + x]);
            assert!((d - 6.0).abs() < 6e-3, "({x}, {y}): {d}");
        }
    }
    drop(raster);
    common::finish(ctx);
}

#[test]
fn lambert_shading_is_luminance_calibrated() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    // Reflectance 0.5 under 200 lux ambient + 300 lux head-on directional: 0.5·500/π cd/m².
    let s = scene(
        r#"
[camera]
position = [0.0, 0.0, 0.0]
far_m = 100.0

[background]
luminance_cd_m2 = 25.0

[[light]]
kind = "ambient"
illuminance_lux = 200.0

[[light]]
kind = "directional"
direction = [0.0, 0.0, -1.0]
illuminance_lux = 300.0

[[object]]
kind = "plane"
size_m = 0.5
translate = [0.0, 0.0, -2.0]
color = [0.5, 0.5, 0.5]
"#,
    );
    let frame = raster.render(&ctx, &s.at_time(0.0), 160, 90).unwrap();
    let centre = frame.color[45 * 160 + 80];
    let expected = 0.5 * 500.0 / std::f32::consts::PI;
    let y = luminance([centre[0], centre[1], centre[2]]);
    assert!((y - expected).abs() < 1e-3 * expected, "{y} vs {expected}");
    let corner = frame.color[0];
    let bg = luminance([corner[0], corner[1], corner[2]]);
    assert!((bg - 25.0).abs() < 0.05, "{bg}");
    assert_eq!(frame.depth_m[0], 100.0);
    drop(raster);
    common::finish(ctx);
}

#[test]
fn shipped_scenes_render_with_finite_colour_and_positive_depth() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    for name in Scene::builtin_names() {
        let s = Scene::load(name).unwrap();
        let state = s.at_time(0.0);
        let frame = raster.render(&ctx, &state, 160, 90).unwrap();
        assert!(
            frame
                .color
                .iter()
                .all(|c| c.iter().all(|v| v.is_finite() && *v >= 0.0)),
            "{name}: non-finite colour"
        );
        let far = state.camera.far_m as f32;
        assert!(
            frame.depth_m.iter().all(|&d| d > 0.0 && d <= far),
            "{name}: depth outside (0, far]"
        );
        let (min, max) = frame
            .depth_m
            .iter()
            .fold((f32::MAX, 0.0f32), |(a, b), &d| (a.min(d), b.max(d)));
        eprintln!(
            "{name}: depth {min:.3}..{max:.2} m, GPU {:.2} ms",
            frame.timings.total_ms()
        );
        if name == "colonnade" {
            // Columns from 0.3 m to tens of metres are all in view.
            assert!(min < 0.5 && max > 20.0, "{min}..{max}");
        }
        if name == "primitives" {
            // The sphere's nearest point is about 0.18 m away.
            assert!(min > 0.15 && min < 0.2, "{min}");
        }
    }
    drop(raster);
    common::finish(ctx);
}

/// Colour resolved by the compute pass (what a GPU does) and by the render pass (what lavapipe
/// does by default) give the same frames: every shipped scene, its hidden layers and its mixed
/// pixels. The compute resolve sums the samples in order and scales by 1/n; lavapipe's render
/// pass gave the same bits, so the bar is a few ulps, and a resolve that read fewer samples
/// than all would miss it at every silhouette.
#[test]
fn colour_resolved_in_compute_equals_the_render_pass_resolve() {
    let ctx = common::gpu();
    let mut rasters = [
        Rasterizer::with_colour_resolve(&ctx, false).unwrap(),
        Rasterizer::with_colour_resolve(&ctx, true).unwrap(),
    ];
    for r in rasters.iter_mut() {
        r.set_mixed_pixels(true);
    }
    let mut edge_pixels = 0usize;
    for name in Scene::builtin_names() {
        let s = Scene::load(name).unwrap();
        let state = s.at_time(0.0);
        let [a, b] = rasters
            .each_mut()
            .map(|r| r.render_layers(&ctx, &state, (120, 68), 2, 0.25).unwrap());
        for (layer, (fa, fb)) in a.iter().zip(&b).enumerate() {
            let worst = fa
                .color
                .iter()
                .zip(&fb.color)
                .flat_map(|(x, y)| x.iter().zip(y))
                .map(|(x, y)| (x - y).abs() / x.abs().max(y.abs()).max(1e-30))
                .fold(0.0f32, f32::max);
            assert!(
                worst <= 4.0 * f32::EPSILON,
                "{name} layer {layer}: relative {worst:e}"
            );
            assert_eq!(fa.depth_m, fb.depth_m, "{name} layer {layer}: depth");
        }
        assert_eq!(a[0].rest, b[0].rest, "{name}: mixed pixels");
        edge_pixels += a[0].rest.iter().filter(|r| r[3] < 1.0).count();
    }
    // the frames had silhouettes, where the samples differ
    assert!(edge_pixels > 100, "{edge_pixels} mixed pixels");
    drop(rasters);
    common::finish(ctx);
}

/// The draw's half-colour diagnostic (`bench --draw-half-colour`) draws the same frame to half
/// precision: within 2⁻¹⁰ of each value (half floats keep 11 bits) on the default scene, whose
/// light stays under half's 65504 cd/m²; and not to the bit, so the diagnostic did change the
/// format.
#[test]
fn the_half_colour_draw_is_the_frame_to_half_precision() {
    use ocular::render::{SurfaceInputs, MSAA_SAMPLES};
    let ctx = common::gpu();
    let s = Scene::load("primitives").unwrap();
    let state = s.at_time(0.0);
    let full = Rasterizer::new(&ctx)
        .unwrap()
        .render(&ctx, &state, 120, 68)
        .unwrap();
    let half = Rasterizer::for_diagnostic(&ctx, SurfaceInputs::Covered, MSAA_SAMPLES, true)
        .unwrap()
        .render(&ctx, &state, 120, 68)
        .unwrap();
    let worst = full
        .color
        .iter()
        .zip(&half.color)
        .flat_map(|(x, y)| x[..3].iter().zip(&y[..3]))
        .map(|(x, y)| (x - y).abs() / x.abs().max(1e-6))
        .fold(0.0f32, f32::max);
    assert!(worst <= 1.0 / 1024.0, "relative {worst:e}");
    assert!(worst > 0.0, "the half-colour draw changed nothing");
    assert_eq!(full.depth_m, half.depth_m);
    common::finish(ctx);
}

#[test]
fn graphics_pipeline_checks_its_framebuffers() {
    let ctx = common::gpu();
    let pipeline = GraphicsPipeline::builder(
        "check",
        ocular::shaders::RENDER_RASTER_VERT,
        ocular::shaders::RENDER_RASTER_FRAG,
    )
    .vertex_layout(
        36,
        &[
            VertexAttribute {
                location: 0,
                format: VertexFormat::Float3,
                offset: 0,
            },
            VertexAttribute {
                location: 1,
                format: VertexFormat::Float3,
                offset: 12,
            },
            VertexAttribute {
                location: 2,
                format: VertexFormat::Float2,
                offset: 24,
            },
            // the vertex's reach (raster.vert)
            VertexAttribute {
                location: 3,
                format: VertexFormat::Float,
                offset: 32,
            },
        ],
    )
    .bindings(&[BindingKind::UniformBuffer, BindingKind::SampledImage])
    // albedo, emission and the depth range (raster_shade.glsl)
    .push_constants::<[f32; 12]>()
    .samples(4)
    .color_target(TexelFormat::Rgba16Float, true)
    .color_target(TexelFormat::R32Float, false)
    .depth_target(TexelFormat::D32Float, DepthCompare::Greater)
    .build(&ctx)
    .unwrap();
    let target = |format, samples| {
        Image::new_2d(
            &ctx,
            "target",
            8,
            8,
            format,
            ImageUsage {
                color_attachment: format != TexelFormat::D32Float,
                depth_attachment: format == TexelFormat::D32Float,
                samples,
                ..ImageUsage::default()
            },
        )
        .unwrap()
    };
    let color = target(TexelFormat::Rgba16Float, 4);
    let single = target(TexelFormat::Rgba16Float, 1);
    let depth_values = target(TexelFormat::R32Float, 4);
    let depth = target(TexelFormat::D32Float, 4);
    // Missing resolve target.
    let err = pipeline
        .framebuffer(&ctx, &[&color, &depth_values], &[], Some(&depth))
        .err()
        .unwrap();
    assert!(matches!(err, GpuError::Usage { .. }), "{err}");
    // A single-sample image where a multisampled one belongs.
    let err = pipeline
        .framebuffer(&ctx, &[&single, &depth_values], &[&single], Some(&depth))
        .err()
        .unwrap();
    assert!(err.to_string().contains("sample"), "{err}");
    let fb = pipeline
        .framebuffer(&ctx, &[&color, &depth_values], &[&single], Some(&depth))
        .unwrap();
    // Drawing outside a render pass is refused before the driver sees it.
    let vertices = ocular::gpu::Buffer::new(&ctx, "v", 64, ocular::gpu::Residency::Device).unwrap();
    let err = ctx
        .submit(|rec| rec.draw(&pipeline, &[], &[0f32; 8], Some(&vertices), 3))
        .unwrap_err();
    assert!(err.to_string().contains("outside a render pass"), "{err}");
    // An empty render pass clears and ends cleanly.
    ctx.submit(|rec| {
        rec.begin_render_pass(&pipeline, &fb, &[[0.0; 4], [1.0; 4]], 0.0)?;
        rec.end_render_pass()
    })
    .unwrap();
    drop((fb, pipeline, color, single, depth_values, depth, vertices));
    common::finish(ctx);
}

#[test]
fn point_lights_fall_off_with_the_square_of_distance() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    // 400 cd at the eye, plane 2 m away: 100 lux at the centre, 0.5 · 100 / π cd/m².
    let s = scene(
        r#"
[camera]
position = [0.0, 0.0, 0.0]
far_m = 100.0

[[light]]
kind = "point"
position = [0.0, 0.0, 0.0]
intensity_cd = 400.0

[[object]]
kind = "plane"
size_m = 10.0
translate = [0.0, 0.0, -2.0]
color = [0.5, 0.5, 0.5]
"#,
    );
    let frame = raster.render(&ctx, &s.at_time(0.0), 160, 90).unwrap();
    // The pixel just right of and below the centre: its ray is 0.37° off axis, cos³ ≈ 1.
    let c = frame.color[45 * 160 + 80];
    let expected = 0.5 * 100.0 / std::f32::consts::PI;
    let y = luminance([c[0], c[1], c[2]]);
    assert!((y - expected).abs() < 2e-3 * expected, "{y} vs {expected}");
    drop(raster);
    common::finish(ctx);
}

#[test]
fn textures_are_srgb_decoded_and_mapped_across_the_surface() {
    let dir = common::temp_dir("texture");
    // Left half mid-grey (sRGB 128), right half pure red.
    let texture = image::RgbaImage::from_fn(4, 1, |x, _| {
        if x < 2 {
            image::Rgba([128, 128, 128, 255])
        } else {
            image::Rgba([255, 0, 0, 255])
        }
    });
    texture.save(dir.join("halves.png")).unwrap();
    let text = r#"
[camera]
position = [0.0, 0.0, 0.0]
fov_y_deg = 30.0
far_m = 100.0

[[light]]
kind = "ambient"
illuminance_lux = 314.159265

[[object]]
kind = "plane"
size_m = [1.0, 0.5]
translate = [0.0, 0.0, -2.0]
color = [1.0, 1.0, 1.0]
texture = "halves.png"
"#;
    let s = Scene::from_toml(text, "textured", &dir).unwrap();
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let frame = raster.render(&ctx, &s.at_time(0.0), 160, 90).unwrap();
    // The plane spans x = 80 ± 42 pixels; u = 1/4 and 3/4 lie at x ≈ 59 and 101.
    let grey = frame.color[45 * 160 + 59];
    let red = frame.color[45 * 160 + 101];
    // Luminance = texel (linear) · 1 · 314.16 / π = 100 · texel.
    let grey_linear = ((128.0f32 / 255.0 + 0.055) / 1.055).powf(2.4);
    for k in 0..3 {
        assert!((grey[k] - 100.0 * grey_linear).abs() < 0.1, "{grey:?}");
    }
    assert!(
        (red[0] - 100.0).abs() < 0.1 && red[1] < 0.01 && red[2] < 0.01,
        "{red:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
    drop(raster);
    common::finish(ctx);
}

#[test]
fn empty_scene_is_background_at_far_and_sizes_can_change() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let s = scene(
        r#"
[camera]
position = [0.0, 0.0, 0.0]
far_m = 30.0

[background]
color = [0.5, 1.0, 2.0]
"#,
    );
    for (w, h) in [(160, 90), (64, 48), (1, 1)] {
        let frame = raster.render(&ctx, &s.at_time(0.0), w, h).unwrap();
        assert_eq!(frame.color.len(), (w * h) as usize);
        assert!(frame.color.iter().all(|c| *c == [0.5, 1.0, 2.0, 1.0]));
        assert!(frame.depth_m.iter().all(|&d| d == 30.0));
    }
    assert!(raster.render(&ctx, &s.at_time(0.0), 0, 10).is_err());
    drop(raster);
    common::finish(ctx);
}

/// A spectacle lens moves every direction it is looked through: a −6.84 D sphere with a
/// −2.00 D cylinder at axis 180, 12 mm in front of the cornea, seen from the entrance pupil
/// 3.05 mm behind it, minifies by the power factor 1/(1 − h·F) of each principal meridian
/// (textbook spectacle magnification, computed here per meridian): horizontally by the
/// sphere's, vertically by sphere + cylinder's. The rasterised square's width and height
/// follow; its depth (the object's distance) does not change.
#[test]
fn spectacle_magnification_scales_the_view_per_meridian() {
    use ocular::eye::Spectacle;
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let (w, h) = (160u32, 90u32);
    let fov = 30.0f64;
    let (half, distance) = (0.2, 2.0);
    let s = square_scene(half, distance, fov);
    let spectacle = Spectacle {
        sphere_d: -6.84,
        cylinder_d: -2.0,
        axis_deg: 180.0,
        vertex_mm: 12.0,
    };
    let h_m = (12.0 + 3.05) * 1e-3;
    let expected = [1.0 / (1.0 + h_m * 6.84), 1.0 / (1.0 + h_m * 8.84)];
    let side = 0.5 * f64::from(h) / (fov.to_radians() / 2.0).tan() * 2.0 * half / distance;
    // Width along the central rows and height along the central columns, from coverage.
    let extent = |frame: &ocular::render::Frame| {
        let cov = |x: u32, y: u32| {
            let c = frame.color[(y * w + x) as usize];
            f64::from(luminance([c[0], c[1], c[2]])) / 100.0
        };
        let width: f64 = (43..47)
            .map(|y| (0..w).map(|x| cov(x, y)).sum::<f64>())
            .sum::<f64>()
            / 4.0;
        let height: f64 = (78..82)
            .map(|x| (0..h).map(|y| cov(x, y)).sum::<f64>())
            .sum::<f64>()
            / 4.0;
        [width, height]
    };
    let plain = extent(&raster.render(&ctx, &s.at_time(0.0), w, h).unwrap());
    raster.set_view_magnification(spectacle.angular_magnification(3.05));
    let frame = raster.render(&ctx, &s.at_time(0.0), w, h).unwrap();
    let seen = extent(&frame);
    eprintln!(
        "square {side:.2} px: plain {plain:?}, through the spectacle {seen:?}, expected {:?}",
        [side * expected[0], side * expected[1]]
    );
    for axis in 0..2 {
        assert!((plain[axis] - side).abs() < 0.6, "{plain:?} vs {side}");
        assert!(
            (seen[axis] - side * expected[axis]).abs() < 0.6,
            "axis {axis}: {} px, expected {}",
            seen[axis],
            side * expected[axis]
        );
    }
    assert!(frame
        .depth_m
        .iter()
        .all(|&d| d == 100.0 || ((f64::from(d) - distance) / distance).abs() < 1e-4));
    drop(raster);
    common::finish(ctx);
}
