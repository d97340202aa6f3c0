//! The Rust mirror of the frame's uniform block against every splat shader that declares it
//! (SPIR-V reflection; the build keeps debug names): every member's name and offset, and the
//! block's size. (Push-constant structs, made with `shader_block!`, are checked member by
//! member when their pipelines are built.)

use super::FrameUniform;
use crate::gpu::{reflect, BlockLayout};

/// The layout a `#[repr(C)]` struct gives the named fields, in the order given.
macro_rules! layout_of {
    ($t:ty { $($field:ident),* $(,)? }) => {
        BlockLayout {
            bytes: std::mem::size_of::<$t>() as u32,
            members: vec![$((stringify!($field).to_string(), std::mem::offset_of!($t, $field) as u32)),*],
        }
    };
}

fn frame_uniform() -> BlockLayout {
    layout_of!(FrameUniform {
        width,
        height,
        tiles_x,
        tiles_y,
        tile_size,
        object_count,
        max_radius,
        fragment_count,
        dioptre_min,
        dioptre_step,
        merge_min_radius,
        merge_color_error,
        merge_dioptre_tolerance,
        focal_px,
        group_tolerance_d,
        blend_mode,
        wide_field,
        saturation_epsilon,
        fragments_per_chunk,
        layers,
        layered,
        radius_step,
    })
}

#[test]
fn the_frame_block_matches_its_rust_struct_member_by_member() {
    let splat: Vec<_> = crate::shaders::ALL
        .iter()
        .filter(|(path, _)| path.starts_with("render/splat/"))
        .collect();
    assert!(splat.len() >= 10, "{} splat shaders", splat.len());
    let mut readers = 0;
    for (path, spirv) in splat {
        let r = reflect(spirv).unwrap();
        let uniforms: Vec<_> = r.bindings.iter().filter(|b| b.block.is_some()).collect();
        match uniforms[..] {
            [] => {}
            [frame] => {
                // passes bind it by this name
                assert_eq!(frame.name, "FrameUniform", "{path}");
                assert_eq!(frame.block.as_ref(), Some(&frame_uniform()), "{path}");
                readers += 1;
            }
            _ => panic!("{path}: more than one uniform block"),
        }
    }
    assert!(readers >= 7, "{readers} shaders read the frame block");
}

/// Negative control: the comparison sees a swap of two same-typed members, which a size
/// check cannot.
#[test]
fn a_swapped_member_is_seen() {
    let mut swapped = frame_uniform();
    swapped.members.swap(0, 1);
    let (a, b) = (swapped.members[0].1, swapped.members[1].1);
    swapped.members[0].1 = b;
    swapped.members[1].1 = a;
    let r = reflect(crate::shaders::RENDER_SPLAT_MERGE_COMP).unwrap();
    let frame = r.bindings.iter().find_map(|b| b.block.as_ref()).unwrap();
    assert_eq!(frame.bytes, swapped.bytes);
    assert_ne!(frame, &swapped);
    assert_eq!(frame, &frame_uniform());
}
