//! The Rust mirrors of the splat shaders' uniform and push-constant blocks against the
//! compiled shaders (SPIR-V reflection; the build keeps debug names): every member's name and
//! offset, and the block's size. Pipelines check push-constant sizes when they are built; this
//! also catches two members swapped or renamed on one side only.

use super::band_plan::BandPlanPush;
use super::bands::BandPush;
use super::fragments::FragmentsPush;
use super::input::InputPush;
use super::merge::MergePush;
use super::prefix_sum::PrefixSumPush;
use super::psf_texture::PsfTexturePush;
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
        merge_color_tolerance,
        merge_dioptre_tolerance,
        focal_px,
        group_tolerance_d,
        blend_mode,
        wide_field,
        saturation_epsilon,
        fragments_per_chunk,
        layers,
    })
}

fn band_push() -> BlockLayout {
    layout_of!(BandPush {
        slot,
        entry_capacity
    })
}

/// (shader, whether it reads the frame block, its push-constant block if it has one)
type ShaderBlocks = (&'static str, &'static [u8], bool, Option<BlockLayout>);

fn splat_shaders() -> Vec<ShaderBlocks> {
    use crate::shaders::*;
    vec![
        (
            "input",
            RENDER_SPLAT_INPUT_COMP,
            false,
            Some(layout_of!(InputPush {
                width,
                height,
                layer,
                write_previous,
                near_m,
                far_m
            })),
        ),
        (
            "fragments",
            RENDER_SPLAT_FRAGMENTS_COMP,
            true,
            Some(layout_of!(FragmentsPush {
                pupil_visibility,
                focus_d,
                parallax_px_per_d
            })),
        ),
        (
            "merge",
            RENDER_SPLAT_MERGE_COMP,
            true,
            Some(layout_of!(MergePush {
                block_size,
                blur_per_block
            })),
        ),
        ("tile count", RENDER_SPLAT_TILE_COUNT_COMP, true, None),
        (
            "prefix sum",
            RENDER_SPLAT_PREFIX_SUM_COMP,
            false,
            Some(layout_of!(PrefixSumPush { phase, count })),
        ),
        (
            "psf texture",
            RENDER_SPLAT_PSF_TEXTURE_COMP,
            true,
            Some(layout_of!(PsfTexturePush {
                first_level,
                end_level,
                first_texel,
                node,
                corner_weights,
                block_side,
                pad0,
                pad1,
                pad2
            })),
        ),
        (
            "tile fill",
            RENDER_SPLAT_TILE_FILL_COMP,
            true,
            Some(band_push()),
        ),
        (
            "tile sort",
            RENDER_SPLAT_TILE_SORT_COMP,
            false,
            Some(band_push()),
        ),
        (
            "convolve",
            RENDER_SPLAT_CONVOLVE_COMP,
            true,
            Some(band_push()),
        ),
        (
            "band plan",
            RENDER_SPLAT_BAND_PLAN_COMP,
            false,
            Some(layout_of!(BandPlanPush {
                tiles_x,
                tiles,
                capacity,
                slots
            })),
        ),
    ]
}

#[test]
fn shader_blocks_match_their_rust_structs_member_by_member() {
    for (name, spirv, reads_frame, push) in splat_shaders() {
        let r = reflect(spirv).unwrap();
        let uniforms: Vec<_> = r.bindings.iter().filter(|b| b.block.is_some()).collect();
        if reads_frame {
            assert_eq!(uniforms.len(), 1, "{name}: one uniform block");
            // passes bind it by this name
            assert_eq!(uniforms[0].name, "FrameUniform", "{name}");
            assert_eq!(uniforms[0].block.as_ref(), Some(&frame_uniform()), "{name}");
        } else {
            assert!(uniforms.is_empty(), "{name}: no frame block");
        }
        assert_eq!(r.push_constants, push, "{name}: push constants");
    }
}

/// Negative control: the comparison sees a swap of two same-typed members, which a size
/// check cannot.
#[test]
fn a_swapped_member_is_seen() {
    let mut swapped = band_push();
    swapped.members.swap(0, 1);
    let (a, b) = (swapped.members[0].1, swapped.members[1].1);
    swapped.members[0].1 = b;
    swapped.members[1].1 = a;
    let r = reflect(crate::shaders::RENDER_SPLAT_TILE_SORT_COMP).unwrap();
    assert_eq!(r.push_constants.as_ref().map(|p| p.bytes), Some(8));
    assert_ne!(r.push_constants, Some(swapped));
}
