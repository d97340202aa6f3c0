//! Rust structs that mirror GLSL blocks (push constants): declared once with `shader_block!`,
//! which makes the struct `#[repr(C)]` and records its members' names and offsets, so that a
//! pipeline checks them against the shader's block member by member when it is built (a size
//! check alone misses two members swapped or renamed on one side).

use super::reflect::BlockLayout;

/// A `#[repr(C)]` Pod value a shader block holds. A struct made with `shader_block!` lists its
/// members; a plain value (a `u32`, an array) has none to check, only its size.
pub trait ShaderBlock: bytemuck::Pod {
    /// (name, byte offset) of each member in declaration order, if known.
    fn members() -> Option<Vec<(&'static str, u32)>> {
        None
    }
}

impl ShaderBlock for () {}
impl ShaderBlock for u32 {}
impl ShaderBlock for f32 {}
impl<T: ShaderBlock, const N: usize> ShaderBlock for [T; N] where [T; N]: bytemuck::Pod {}

/// Declares a struct that mirrors a GLSL block: as written, plus `#[repr(C)]` and a
/// [`ShaderBlock`] impl listing its fields. The struct's own attributes (doc comment, derives,
/// which must include `bytemuck::Pod` and `bytemuck::Zeroable`) come first.
macro_rules! shader_block {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$field_meta:meta])* $field_vis:vis $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        $vis struct $name {
            $( $(#[$field_meta])* $field_vis $field : $ty ),*
        }

        impl $crate::gpu::ShaderBlock for $name {
            fn members() -> Option<Vec<(&'static str, u32)>> {
                Some(vec![$((stringify!($field), std::mem::offset_of!($name, $field) as u32)),*])
            }
        }
    };
}
pub(crate) use shader_block;

/// Whether the struct `T` matches the shader's block `block` (None: the shader has none):
/// its size, and when `T` lists its members and the module kept its debug names, every
/// member's name and offset.
pub(crate) fn check_block<T: ShaderBlock>(
    what: &str,
    block: Option<&BlockLayout>,
) -> Result<(), String> {
    let bytes = std::mem::size_of::<T>() as u32;
    let shader_bytes = block.map_or(0, |b| b.bytes);
    if bytes != shader_bytes {
        return Err(format!(
            "the shader's {what} block is {shader_bytes} bytes, the pass's struct {bytes}"
        ));
    }
    let (Some(members), Some(block)) = (T::members(), block) else {
        return Ok(());
    };
    if block.members.iter().any(|(name, _)| name.is_empty()) {
        return Ok(());
    }
    let shader: Vec<(&str, u32)> = block
        .members
        .iter()
        .map(|(n, o)| (n.as_str(), *o))
        .collect();
    if members != shader {
        let show = |m: &[(&str, u32)]| {
            m.iter()
                .map(|(n, o)| format!("{n}@{o}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        return Err(format!(
            "the shader's {what} block has members {}, the pass's struct {}",
            show(&shader),
            show(&members)
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    shader_block! {
        /// Mirrors `BandPush` (glsl/common/band.glsl).
        #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
        struct Band {
            slot: u32,
            entry_capacity: u32,
        }
    }

    shader_block! {
        /// The same members swapped: the same size, which a size check cannot tell apart.
        #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
        struct Swapped {
            entry_capacity: u32,
            slot: u32,
        }
    }

    #[test]
    fn members_are_checked_by_name_and_offset() {
        let sort = crate::gpu::reflect(crate::shaders::RENDER_SPLAT_TILE_SORT_COMP).unwrap();
        let block = sort.push_constants.as_ref();
        assert_eq!(
            Band::members().unwrap(),
            [("slot", 0), ("entry_capacity", 4)]
        );
        assert!(check_block::<Band>("push-constant", block).is_ok());
        let swapped = check_block::<Swapped>("push-constant", block).unwrap_err();
        assert!(
            swapped.contains(
                "members slot@0, entry_capacity@4, the pass's struct entry_capacity@0, slot@4"
            ),
            "{swapped}"
        );
        // A plain value is checked by its size alone.
        assert!(check_block::<[u32; 2]>("push-constant", block).is_ok());
        let size = check_block::<u32>("push-constant", block).unwrap_err();
        assert!(
            size.contains("block is 8 bytes, the pass's struct 4"),
            "{size}"
        );
        assert!(check_block::<()>("push-constant", None).is_ok());
    }
}
