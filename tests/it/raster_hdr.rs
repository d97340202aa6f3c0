//! HDR without a ceiling (issue 20, defect 7): the rasteriser's colour targets were half float,
//! which clipped every value above 65504 cd/m² (a lamp, the sun) without a word.

use crate::common;

use std::path::Path;

use ocular::render::Rasterizer;
use ocular::scene::Scene;

#[test]
fn emitters_brighter_than_half_float_keep_their_luminance() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    for luminance in [1.0e5f32, 3.0e6, 40.0] {
        // A black, unlit plane filling the view that emits `luminance` cd/m² in white.
        let text = format!(
            r#"
[camera]
position = [0.0, 0.0, 0.0]
yaw_deg = 0.0
fov_y_deg = 40.0
far_m = 100.0

[background]
color = [0.0, 0.0, 0.0]

[[object]]
kind = "plane"
size_m = 50.0
translate = [0.0, 0.0, -2.0]
color = [0.0, 0.0, 0.0]
emission_cd_m2 = {luminance}
"#
        );
        let scene = Scene::from_toml(&text, "hdr", Path::new(".")).unwrap();
        let frame = raster.render(&ctx, &scene.at_time(0.0), 32, 18).unwrap();
        for p in &frame.color {
            for c in &p[..3] {
                assert!(
                    (c - luminance).abs() <= 1e-5 * luminance,
                    "{luminance} cd/m² emitter rendered as {c}"
                );
            }
        }
    }
    common::finish(ctx);
}
