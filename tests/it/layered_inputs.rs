//! Layered EXR input (parts layer0, layer1, … with R, G, B, Z) and the command-line checks of
//! the partial-occlusion options (--views, --layers, --truth views).

use crate::common;
use crate::common::{ocular_run, temp_dir};

use common::blender::{options, plane, uniform_rgb, write_multi_part, Plane};
use ocular::inputs::load;

const W: usize = 16;
const H: usize = 8;

fn layer(value: f32, z: impl Fn(usize) -> f32) -> Vec<Plane> {
    let n = W * H;
    let mut planes = uniform_rgb(n, [value, 2.0 * value, 3.0 * value]);
    planes.push(plane("Z", (0..n).map(z).collect()));
    planes
}

#[test]
fn parts_layer0_and_layer1_give_the_frame_and_a_hidden_layer() {
    let dir = temp_dir("parts");
    let path = dir.join("layers.exr");
    // layer 1 is there only in the left half (behind a near card)
    write_multi_part(
        &path,
        (W, H),
        vec![
            (
                "layer0",
                layer(1.0, |i| if i % W < W / 2 { 0.5 } else { 4.0 }),
            ),
            (
                "layer1",
                layer(10.0, |i| if i % W < W / 2 { 4.0 } else { f32::INFINITY }),
            ),
        ],
    );
    let input = load(&options(&path)).unwrap();
    assert_eq!(
        (input.color.width, input.color.height),
        (W as u32, H as u32)
    );
    assert_eq!(input.color.pixels[0], [1.0, 2.0, 3.0, 1.0]);
    assert_eq!(input.depth_m[0], 0.5);
    assert_eq!(input.hidden_layers.len(), 1);
    let (color, depth) = &input.hidden_layers[0];
    for i in 0..W * H {
        if i % W < W / 2 {
            assert_eq!(depth[i], 4.0);
            assert_eq!(color[i], [10.0, 20.0, 30.0, 1.0]);
        } else {
            assert!(depth[i].is_infinite());
            assert_eq!(color[i], [0.0; 4]);
        }
    }
    // the same file as --depth is accepted; another file is not
    let mut o = options(&path);
    o.depth = Some(path.clone());
    assert_eq!(load(&o).unwrap().hidden_layers.len(), 1);
    o.depth = Some(dir.join("other.exr"));
    let e = load(&o).unwrap_err().to_string();
    assert!(e.contains("--depth") && e.contains("layered EXR"), "{e}");
}

#[test]
fn a_gap_or_a_missing_channel_is_refused() {
    let dir = temp_dir("refused");
    let gap = dir.join("gap.exr");
    write_multi_part(
        &gap,
        (W, H),
        vec![
            ("layer0", layer(1.0, |_| 1.0)),
            ("layer2", layer(1.0, |_| 2.0)),
        ],
    );
    let e = load(&options(&gap)).unwrap_err().to_string();
    assert!(e.contains("layer2") && e.contains("without gaps"), "{e}");
    let no_z = dir.join("noz.exr");
    let mut planes = layer(1.0, |_| 1.0);
    planes.pop();
    write_multi_part(&no_z, (W, H), vec![("layer0", planes)]);
    let e = load(&options(&no_z)).unwrap_err().to_string();
    assert!(e.contains("no channel Z"), "{e}");
}

fn code_and_stderr(args: &[&str]) -> (i32, String) {
    let out = ocular_run(args);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

#[test]
fn new_options_are_range_checked_where_parsed() {
    for (args, needle) in [
        (
            vec!["render", "--method", "views", "--views", "1"],
            "--views",
        ),
        (
            vec!["render", "--method", "views", "--views", "70000"],
            "--views",
        ),
        (vec!["render", "--layers", "0"], "--layers"),
        (vec!["render", "--layers", "9"], "--layers"),
        (
            vec!["compare", "--truth", "views", "--views", "x"],
            "--views",
        ),
        (vec!["compare", "--layers", "12"], "--layers"),
        (
            vec!["render", "--views", "64"],
            "--views applies to --method views",
        ),
        (
            vec!["render", "--method", "reference", "--layers", "2"],
            "--layers applies",
        ),
        (
            vec!["compare", "--views", "64"],
            "--views applies to --truth views",
        ),
    ] {
        let (code, err) = code_and_stderr(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(err.trim().lines().count() <= 3, "{args:?}: {err}");
    }
    let (code, err) = code_and_stderr(&[
        "render", "--method", "views", "--color", "x.exr", "--fov-y", "30",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--method views"), "{err}");
}
