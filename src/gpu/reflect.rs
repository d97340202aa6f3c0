//! What a SPIR-V module declares, read from its words: the set-0 bindings (their names, kind
//! and whether the shader reads, writes or both) and the size of its push-constant block.
//! Pipelines take their descriptor-set layout from it, passes bind resources by the names it
//! reports (src/gpu/bind.rs), and the recorder derives barriers from the access
//! (src/gpu/access.rs): the binding order is written once, in the shader.

use ash::vk;

/// The kind of resource a shader binding expects: what reflection reads, so it lives here and
/// the pipelines built from a reflection depend on it, not the reverse.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    StorageBuffer,
    UniformBuffer,
    /// `sampler2D` / `sampler3D`: image plus sampler.
    SampledImage,
    /// `image2D` / `image3D` with imageLoad / imageStore.
    StorageImage,
}

impl BindingKind {
    pub(crate) fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::SampledImage => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
        }
    }
}

/// How a shader uses a binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Read,
    Write,
    ReadWrite,
}

impl Access {
    pub fn reads(self) -> bool {
        self != Access::Write
    }

    pub fn writes(self) -> bool {
        self != Access::Read
    }
}

/// One binding of descriptor set 0.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReflectedBinding {
    pub binding: u32,
    /// The GLSL name a pass binds it by: a buffer or uniform block's block name (`Radii` in
    /// `buffer Radii { vec4 radii[]; }`), an image's or sampler's variable name. Empty when
    /// the module's debug names were stripped.
    pub name: String,
    pub kind: BindingKind,
    pub access: Access,
    /// Uniform buffers: the block's layout (a Rust struct that mirrors it is checked against it).
    pub block: Option<BlockLayout>,
}

/// The explicit layout of a uniform or push-constant block: its size and its members' names
/// (from the module's debug names; empty when stripped) and offsets, in declaration order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BlockLayout {
    pub bytes: u32,
    pub members: Vec<(String, u32)>,
}

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Reflection {
    /// Set-0 bindings in binding order.
    pub bindings: Vec<ReflectedBinding>,
    /// Bytes of the push-constant block (0 without one).
    pub push_constant_bytes: u32,
    /// The push-constant block's layout (None without one).
    pub push_constants: Option<BlockLayout>,
}

mod op {
    pub const NAME: u32 = 5;
    pub const MEMBER_NAME: u32 = 6;
    pub const DECORATE: u32 = 71;
    pub const MEMBER_DECORATE: u32 = 72;
    pub const TYPE_INT: u32 = 21;
    pub const TYPE_FLOAT: u32 = 22;
    pub const TYPE_VECTOR: u32 = 23;
    pub const TYPE_MATRIX: u32 = 24;
    pub const TYPE_IMAGE: u32 = 25;
    pub const TYPE_SAMPLED_IMAGE: u32 = 27;
    pub const TYPE_ARRAY: u32 = 28;
    pub const TYPE_RUNTIME_ARRAY: u32 = 29;
    pub const TYPE_STRUCT: u32 = 30;
    pub const TYPE_POINTER: u32 = 32;
    pub const CONSTANT: u32 = 43;
    pub const VARIABLE: u32 = 59;
}

mod deco {
    pub const BUFFER_BLOCK: u32 = 3;
    pub const ARRAY_STRIDE: u32 = 6;
    pub const NON_WRITABLE: u32 = 24;
    pub const NON_READABLE: u32 = 25;
    pub const BINDING: u32 = 33;
    pub const DESCRIPTOR_SET: u32 = 34;
    pub const OFFSET: u32 = 35;
}

mod class {
    pub const UNIFORM_CONSTANT: u32 = 0;
    pub const UNIFORM: u32 = 2;
    pub const PUSH_CONSTANT: u32 = 9;
    pub const STORAGE_BUFFER: u32 = 12;
}

#[derive(Clone, Debug)]
enum Type {
    Scalar(u32),
    Vector(u32, u32),
    Matrix(u32, u32),
    Image { sampled: u32 },
    SampledImage,
    Array(u32, u32),
    RuntimeArray,
    Struct(Vec<u32>),
    Pointer(u32),
    Other,
}

#[derive(Default)]
struct Module {
    types: std::collections::HashMap<u32, Type>,
    constants: std::collections::HashMap<u32, u32>,
    /// (id, decoration) → first literal (or 0).
    decorations: std::collections::HashMap<(u32, u32), u32>,
    /// (struct, member, decoration) → first literal (or 0).
    member_decorations: std::collections::HashMap<(u32, u32, u32), u32>,
    /// (variable, pointer type, storage class)
    variables: Vec<(u32, u32, u32)>,
    /// id → debug name (OpName).
    names: std::collections::HashMap<u32, String>,
    /// (struct, member) → debug name.
    member_names: std::collections::HashMap<(u32, u32), String>,
}

/// A SPIR-V literal string: UTF-8 bytes packed little-endian into words, nul-terminated.
fn literal_string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

/// Reads `spirv` (bytes of a SPIR-V module). Errors name what is malformed.
pub fn reflect(spirv: &[u8]) -> Result<Reflection, String> {
    let words = ash::util::read_spv(&mut std::io::Cursor::new(spirv))
        .map_err(|e| format!("not a SPIR-V module ({e})"))?;
    if words.len() < 5 || words[0] != 0x0723_0203 {
        return Err("not a SPIR-V module (magic number)".into());
    }
    let module = parse(&words[5..])?;
    module.reflection()
}

fn parse(mut words: &[u32]) -> Result<Module, String> {
    let mut m = Module::default();
    while !words.is_empty() {
        let count = (words[0] >> 16) as usize;
        let opcode = words[0] & 0xffff;
        if count == 0 || count > words.len() {
            return Err("truncated SPIR-V instruction".into());
        }
        let a = &words[1..count];
        let at = |i: usize| a.get(i).copied().unwrap_or(0);
        match opcode {
            op::DECORATE => {
                m.decorations.insert((at(0), at(1)), at(2));
            }
            op::NAME if a.len() > 1 => {
                m.names.insert(at(0), literal_string(&a[1..]));
            }
            op::MEMBER_NAME if a.len() > 2 => {
                m.member_names
                    .insert((at(0), at(1)), literal_string(&a[2..]));
            }
            op::MEMBER_DECORATE => {
                m.member_decorations.insert((at(0), at(1), at(2)), at(3));
            }
            op::TYPE_INT | op::TYPE_FLOAT => {
                m.types.insert(at(0), Type::Scalar(at(1) / 8));
            }
            op::TYPE_VECTOR => {
                m.types.insert(at(0), Type::Vector(at(1), at(2)));
            }
            op::TYPE_MATRIX => {
                m.types.insert(at(0), Type::Matrix(at(1), at(2)));
            }
            op::TYPE_IMAGE => {
                m.types.insert(at(0), Type::Image { sampled: at(6) });
            }
            op::TYPE_SAMPLED_IMAGE => {
                m.types.insert(at(0), Type::SampledImage);
            }
            op::TYPE_ARRAY => {
                m.types.insert(at(0), Type::Array(at(1), at(2)));
            }
            op::TYPE_RUNTIME_ARRAY => {
                m.types.insert(at(0), Type::RuntimeArray);
            }
            op::TYPE_STRUCT => {
                m.types.insert(at(0), Type::Struct(a[1..].to_vec()));
            }
            op::TYPE_POINTER => {
                m.types.insert(at(0), Type::Pointer(at(2)));
            }
            op::CONSTANT => {
                m.constants.insert(at(1), at(2));
            }
            op::VARIABLE => m.variables.push((at(1), at(0), at(2))),
            _ => {
                if (20..=39).contains(&opcode) && !a.is_empty() {
                    m.types.entry(at(0)).or_insert(Type::Other);
                }
            }
        }
        words = &words[count..];
    }
    Ok(m)
}

impl Module {
    fn pointee(&self, pointer: u32) -> Option<u32> {
        match self.types.get(&pointer) {
            Some(Type::Pointer(t)) => Some(*t),
            _ => None,
        }
    }

    fn has(&self, id: u32, decoration: u32) -> bool {
        self.decorations.contains_key(&(id, decoration))
    }

    /// Size in bytes of a type as laid out in an explicitly laid-out block.
    fn size_of(&self, id: u32) -> Result<u32, String> {
        Ok(match self.types.get(&id) {
            Some(Type::Scalar(bytes)) => *bytes,
            Some(Type::Vector(component, n)) => self.size_of(*component)? * n,
            Some(Type::Matrix(column, n)) => {
                let stride = self.size_of(*column)?;
                stride * n
            }
            Some(Type::Array(element, length)) => {
                let n = *self
                    .constants
                    .get(length)
                    .ok_or("array length is not a plain constant")?;
                let stride = match self.decorations.get(&(id, deco::ARRAY_STRIDE)) {
                    Some(&s) => s,
                    None => self.size_of(*element)?,
                };
                stride * n
            }
            Some(Type::Struct(members)) => {
                let mut end = 0;
                for (i, &member) in members.iter().enumerate() {
                    let offset = self
                        .member_decorations
                        .get(&(id, i as u32, deco::OFFSET))
                        .copied()
                        .ok_or("struct member without an offset")?;
                    end = end.max(offset + self.size_of(member)?);
                }
                end
            }
            _ => return Err(format!("type %{id} has no size in a block")),
        })
    }

    /// Size, member names and offsets of an explicitly laid-out block.
    fn block_layout(&self, id: u32) -> Result<BlockLayout, String> {
        let count = match self.types.get(&id) {
            Some(Type::Struct(m)) => m.len() as u32,
            _ => 0,
        };
        let members = (0..count)
            .map(|i| {
                let name = self.member_names.get(&(id, i)).cloned().unwrap_or_default();
                let offset = self
                    .member_decorations
                    .get(&(id, i, deco::OFFSET))
                    .copied()
                    .ok_or("block member without an offset")?;
                Ok((name, offset))
            })
            .collect::<Result<Vec<_>, String>>()?;
        Ok(BlockLayout {
            bytes: self.size_of(id)?,
            members,
        })
    }

    /// Access of a buffer block: read-only when every member is NonWritable, write-only when
    /// every member is NonReadable (glslang's `readonly` / `writeonly` on a block).
    fn block_access(&self, variable: u32, block: u32) -> Access {
        let members = match self.types.get(&block) {
            Some(Type::Struct(m)) => m.len() as u32,
            _ => 0,
        };
        let all = |d: u32| {
            self.has(variable, d)
                || (members > 0
                    && (0..members).all(|i| self.member_decorations.contains_key(&(block, i, d))))
        };
        access_of(all(deco::NON_WRITABLE), all(deco::NON_READABLE))
    }

    fn reflection(&self) -> Result<Reflection, String> {
        let mut out = Reflection::default();
        for &(var, pointer, storage) in &self.variables {
            let Some(pointee) = self.pointee(pointer) else {
                continue;
            };
            if storage == class::PUSH_CONSTANT {
                let block = self.block_layout(pointee)?;
                out.push_constant_bytes = block.bytes;
                out.push_constants = Some(block);
                continue;
            }
            let Some(&binding) = self.decorations.get(&(var, deco::BINDING)) else {
                continue;
            };
            if self.decorations.get(&(var, deco::DESCRIPTOR_SET)).copied() != Some(0) {
                continue;
            }
            let mut block = None;
            // Blocks by their block name (instances are often anonymous), opaque resources
            // by their variable name.
            let named = match storage {
                class::UNIFORM_CONSTANT => var,
                _ => pointee,
            };
            let name = self.names.get(&named).cloned().unwrap_or_default();
            let (kind, access) = match (storage, self.types.get(&pointee)) {
                (class::STORAGE_BUFFER, _) => {
                    (BindingKind::StorageBuffer, self.block_access(var, pointee))
                }
                (class::UNIFORM, _) if self.has(pointee, deco::BUFFER_BLOCK) => {
                    (BindingKind::StorageBuffer, self.block_access(var, pointee))
                }
                (class::UNIFORM, _) => {
                    block = Some(self.block_layout(pointee)?);
                    (BindingKind::UniformBuffer, Access::Read)
                }
                (class::UNIFORM_CONSTANT, Some(Type::SampledImage)) => {
                    (BindingKind::SampledImage, Access::Read)
                }
                (class::UNIFORM_CONSTANT, Some(Type::Image { sampled: 2 })) => (
                    BindingKind::StorageImage,
                    access_of(
                        self.has(var, deco::NON_WRITABLE),
                        self.has(var, deco::NON_READABLE),
                    ),
                ),
                _ => {
                    return Err(format!(
                        "binding {binding}: a resource type ocular does not bind"
                    ))
                }
            };
            out.bindings.push(ReflectedBinding {
                binding,
                name,
                kind,
                access,
                block,
            });
        }
        out.bindings.sort_by_key(|b| b.binding);
        Ok(out)
    }
}

fn access_of(non_writable: bool, non_readable: bool) -> Access {
    match (non_writable, non_readable) {
        (true, _) => Access::Read,
        (false, true) => Access::Write,
        (false, false) => Access::ReadWrite,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checked against the GLSL source of the convolution: a sampler, four read-only fragment
    /// ranges (1, 9, 10, 11: `FRAGMENT_BUFFERS`), three read-only list buffers, a write-only
    /// output image, the read-only field table (6), band table (7) and atlas (8), the frame's
    /// uniform block (12), under 8 bytes of band push constants; blocks by their block name,
    /// the sampler and the image by their variable name.
    #[test]
    fn convolve_shader_reflects_as_written() {
        let r = reflect(crate::shaders::RENDER_SPLAT_CONVOLVE_COMP).unwrap();
        assert_eq!(r.push_constant_bytes, 8);
        let got: Vec<(u32, &str, BindingKind, Access)> = r
            .bindings
            .iter()
            .map(|b| (b.binding, b.name.as_str(), b.kind, b.access))
            .collect();
        use Access::*;
        use BindingKind::*;
        assert_eq!(
            got,
            vec![
                (0, "psf_texture", SampledImage, Read),
                (1, "Fragments0", StorageBuffer, Read),
                (2, "Counts", StorageBuffer, Read),
                (3, "Offsets", StorageBuffer, Read),
                (4, "Entries", StorageBuffer, Read),
                (5, "color_out", StorageImage, Write),
                (6, "Field", StorageBuffer, Read),
                (7, "BandTable", StorageBuffer, Read),
                (8, "Atlas", StorageBuffer, Read),
                (9, "Fragments1", StorageBuffer, Read),
                (10, "Fragments2", StorageBuffer, Read),
                (11, "Fragments3", StorageBuffer, Read),
                (12, "FrameUniform", UniformBuffer, Read),
                (13, "LayerAtlas", StorageBuffer, Read),
                (14, "layer_texture", SampledImage, Read),
                (15, "layer_sums", SampledImage, Read),
            ]
        );
        // the frame block: 22 four-byte scalars, std140-packed like repr(C)
        let frame = r.bindings[12].block.as_ref().unwrap();
        assert_eq!(frame.bytes, 88);
        assert_eq!(frame.members[13], ("focal_px".to_string(), 52));
        assert!(r.bindings[11].block.is_none());
        // Merge reads and writes its fragments; tile count reads them and updates counts.
        let merge = reflect(crate::shaders::RENDER_SPLAT_MERGE_COMP).unwrap();
        assert_eq!(merge.bindings[0].access, Read);
        assert_eq!(merge.bindings[1].access, ReadWrite);
        let fill = reflect(crate::shaders::RENDER_SPLAT_FRAGMENTS_COMP).unwrap();
        assert_eq!(fill.bindings[3].access, Write);
        assert!(reflect(&[0u8; 24]).is_err());
    }
}
