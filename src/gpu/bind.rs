//! Binding a pass's resources by the names its shader gives them. The descriptor-set layout is
//! the shader's (SPIR-V reflection, src/gpu/reflect.rs), so the binding order is written once,
//! in GLSL; a pass says what it reads and what it writes under the GLSL names:
//!
//! ```text
//! rec.compute(&pipeline)
//!     .read("Radii", &radii)          // layout(binding = 0) readonly buffer Radii { … };
//!     .write("Fragments", &fragments) // buffer Fragments0 … Fragments3 (a numbered family)
//!     .read("FrameUniform", &uniform) // uniform FrameUniform { … } frame;
//!     .push(&MergePush { … })
//!     .dispatch([x, y, 1])?;
//! ```
//!
//! `read` and `write` are checked against the shader's qualifiers: `read` binds what the
//! shader only reads (`readonly`, a uniform block, a sampler), `write` what it writes
//! (`writeonly` or unqualified). The barriers still come from the shader's own access
//! (src/gpu/access.rs). An unknown, missing or doubly bound name, a resource of the wrong kind
//! or a read/write the shader contradicts is a `GpuError::Usage` naming the pass and binding.

use super::buffer::Buffer;
use super::commands::Recorder;
use super::error::{GpuError, GpuResult};
use super::image::{Image, Sampler};
use super::pipeline::{Binding, ComputePipeline, Layout};
use super::reflect::BindingKind;

/// Something a pass binds under a name: one resource (a buffer, a storage image, an image
/// with its sampler, a `Binding`), or a numbered family bound as `name0`, `name1`, … (an array
/// of bindings; a fragment store's ranges).
pub trait Bindable<'a> {
    /// Each resource with its number in the family; `None` for one bound under the name itself.
    fn resources(self) -> impl IntoIterator<Item = (Option<usize>, Binding<'a>)>;
}

impl<'a> Bindable<'a> for Binding<'a> {
    fn resources(self) -> impl IntoIterator<Item = (Option<usize>, Binding<'a>)> {
        [(None, self)]
    }
}

/// A whole buffer: a storage or uniform buffer.
impl<'a> Bindable<'a> for &'a Buffer {
    fn resources(self) -> impl IntoIterator<Item = (Option<usize>, Binding<'a>)> {
        [(None, Binding::Buffer(self))]
    }
}

/// A storage image (`image2D`, `image3D`).
impl<'a> Bindable<'a> for &'a Image {
    fn resources(self) -> impl IntoIterator<Item = (Option<usize>, Binding<'a>)> {
        [(None, Binding::Storage(self))]
    }
}

/// A sampled image (`sampler2D`, `sampler3D`).
impl<'a> Bindable<'a> for (&'a Image, &'a Sampler) {
    fn resources(self) -> impl IntoIterator<Item = (Option<usize>, Binding<'a>)> {
        [(None, Binding::Sampled(self.0, self.1))]
    }
}

/// A numbered family: element k is bound as `name{k}`.
impl<'a, const N: usize> Bindable<'a> for [Binding<'a>; N] {
    fn resources(self) -> impl IntoIterator<Item = (Option<usize>, Binding<'a>)> {
        self.into_iter().enumerate().map(|(k, b)| (Some(k), b))
    }
}

/// How a pass says it uses a binding.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Use {
    Read,
    Write,
}

/// A pipeline's resources bound by name; `finish` gives them in binding order. Compute passes
/// use it through [`Recorder::compute`]; draws through `GraphicsPipeline::bind`.
pub struct NamedBindings<'a> {
    pass: &'a str,
    layout: &'a Layout,
    slots: Vec<Option<Binding<'a>>>,
    /// The first mistake, reported by `finish` (so calls chain).
    error: Option<String>,
}

impl<'a> NamedBindings<'a> {
    pub(crate) fn new(pass: &'a str, layout: &'a Layout) -> Self {
        NamedBindings {
            pass,
            layout,
            slots: vec![None; layout.slots.len()],
            error: None,
        }
    }

    /// Binds what the shader only reads (`readonly`, a uniform block, a sampler) under `name`.
    pub fn read(mut self, name: &str, resources: impl Bindable<'a>) -> Self {
        self.put(name, resources, Use::Read);
        self
    }

    /// Binds what the shader writes (`writeonly`, or read and written) under `name`.
    pub fn write(mut self, name: &str, resources: impl Bindable<'a>) -> Self {
        self.put(name, resources, Use::Write);
        self
    }

    fn put(&mut self, name: &str, resources: impl Bindable<'a>, usage: Use) {
        for (number, binding) in resources.resources() {
            if self.error.is_some() {
                return;
            }
            let name = match number {
                Some(k) => format!("{name}{k}"),
                None => name.to_string(),
            };
            if let Err(e) = self.put_one(&name, binding, usage) {
                self.error = Some(e);
            }
        }
    }

    fn put_one(&mut self, name: &str, binding: Binding<'a>, usage: Use) -> Result<(), String> {
        let i = self.layout.slot(name)?;
        let slot = &self.layout.slots[i];
        if !binding.matches(slot.kind) {
            return Err(format!(
                "\"{name}\" (binding {i}) is a {} in the shader; {} was given",
                kind_words(slot.kind),
                given_words(&binding)
            ));
        }
        match usage {
            Use::Read if slot.access.writes() => {
                return Err(format!(
                    "the shader writes \"{name}\" (binding {i}, not readonly): bind it with write"
                ))
            }
            Use::Write if !slot.access.writes() => {
                return Err(format!(
                    "the shader only reads \"{name}\" (binding {i}): bind it with read"
                ))
            }
            _ => {}
        }
        let bytes = match binding {
            Binding::Buffer(b) => Some((b, b.size_bytes())),
            Binding::BufferRange(b, _, size) => Some((b, size)),
            _ => None,
        };
        if let (Some(needed), Some((b, bytes))) = (slot.block_bytes, bytes) {
            if bytes < u64::from(needed) {
                return Err(format!(
                    "the uniform block \"{name}\" is {needed} bytes, buffer \"{}\" binds {bytes}",
                    b.name()
                ));
            }
        }
        if self.slots[i].replace(binding).is_some() {
            return Err(format!("\"{name}\" (binding {i}) is bound twice"));
        }
        Ok(())
    }

    /// The resources in binding order, once every binding has one.
    pub fn finish(self) -> GpuResult<Vec<Binding<'a>>> {
        let usage = |message: String| GpuError::Usage {
            pass: self.pass.to_string(),
            message,
        };
        if let Some(e) = self.error {
            return Err(usage(e));
        }
        let missing: Vec<String> = self
            .slots
            .iter()
            .zip(&self.layout.slots)
            .enumerate()
            .filter(|(_, (bound, _))| bound.is_none())
            .map(|(i, (_, slot))| format!("\"{}\" (binding {i})", slot.name))
            .collect();
        if !missing.is_empty() {
            return Err(usage(format!("nothing bound to {}", missing.join(", "))));
        }
        Ok(self.slots.into_iter().flatten().collect())
    }
}

fn kind_words(kind: BindingKind) -> &'static str {
    match kind {
        BindingKind::StorageBuffer => "storage buffer",
        BindingKind::UniformBuffer => "uniform block",
        BindingKind::SampledImage => "sampled image",
        BindingKind::StorageImage => "storage image",
    }
}

fn given_words(binding: &Binding<'_>) -> &'static str {
    match binding {
        Binding::Buffer(_) | Binding::BufferRange(..) => "a buffer",
        Binding::Sampled(..) => "an image with a sampler",
        Binding::Storage(_) => "an image without a sampler",
    }
}

/// One compute dispatch being declared: resources by name, push constants, then `dispatch`.
pub struct Dispatch<'r, 'rec, 'a> {
    rec: &'r mut Recorder<'rec>,
    pipeline: &'a ComputePipeline,
    bindings: NamedBindings<'a>,
    push: &'a [u8],
}

impl<'rec> Recorder<'rec> {
    /// Starts a dispatch of `pipeline`, whose resources are then bound by name (`read`,
    /// `write`) before `dispatch` or `dispatch_indirect` records it.
    pub fn compute<'r, 'a>(&'r mut self, pipeline: &'a ComputePipeline) -> Dispatch<'r, 'rec, 'a> {
        Dispatch {
            rec: self,
            pipeline,
            bindings: NamedBindings::new(&pipeline.name, &pipeline.layout),
            push: &[],
        }
    }
}

impl<'a> Dispatch<'_, '_, 'a> {
    /// See [`NamedBindings::read`].
    pub fn read(mut self, name: &str, resources: impl Bindable<'a>) -> Self {
        self.bindings = self.bindings.read(name, resources);
        self
    }

    /// See [`NamedBindings::write`].
    pub fn write(mut self, name: &str, resources: impl Bindable<'a>) -> Self {
        self.bindings = self.bindings.write(name, resources);
        self
    }

    /// The push constants (a `#[repr(C)]` Pod struct mirroring the shader's block).
    pub fn push<P: bytemuck::Pod>(mut self, push_constants: &'a P) -> Self {
        self.push = bytemuck::bytes_of(push_constants);
        self
    }

    /// Records the dispatch of `groups` workgroups.
    pub fn dispatch(self, groups: [u32; 3]) -> GpuResult<()> {
        let bindings = self.bindings.finish()?;
        self.rec
            .dispatch_bytes(self.pipeline, &bindings, self.push, groups)
    }

    /// Records the dispatch with its workgroup counts read from `args` (three u32 at
    /// `offset`).
    pub fn dispatch_indirect(self, args: &Buffer, offset: u64) -> GpuResult<()> {
        let bindings = self.bindings.finish()?;
        self.rec
            .dispatch_indirect_bytes(self.pipeline, &bindings, self.push, args, offset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::testing::{finish, gpu};
    use crate::gpu::{Edge, ImageUsage, Residency, TexelFormat};

    fn error_of(bound: NamedBindings<'_>) -> String {
        match bound.finish() {
            Ok(_) => panic!("expected an error"),
            Err(e) => e.to_string(),
        }
    }

    /// The layout is the shader's (no list in Rust); every way of binding it wrongly is a
    /// clear error naming the binding; bound by name, a dispatch gives what the positional
    /// one gives.
    #[test]
    fn resources_bind_by_their_glsl_names() {
        let ctx = gpu();
        // glsl/gpu/texture_probe.comp: sampler3D volume (0), readonly buffer Points (1),
        // writeonly buffer Samples (2), a u32 of push constants.
        let probe = ComputePipeline::builder("probe", crate::shaders::GPU_TEXTURE_PROBE_COMP)
            .push_constants::<u32>()
            .build(&ctx)
            .unwrap();
        let names: Vec<(&str, BindingKind)> = probe
            .layout
            .slots
            .iter()
            .map(|s| (s.name.as_str(), s.kind))
            .collect();
        use BindingKind::*;
        assert_eq!(
            names,
            [
                ("volume", SampledImage),
                ("Points", StorageBuffer),
                ("Samples", StorageBuffer)
            ]
        );
        let image = Image::new_3d(
            &ctx,
            "v",
            [4, 4, 4],
            TexelFormat::Rgba32Float,
            ImageUsage::SAMPLED,
        )
        .unwrap();
        let texels: Vec<[f32; 4]> = (0..64).map(|i| [i as f32, 1.0, 2.0, 3.0]).collect();
        image.upload(&ctx, &texels).unwrap();
        let sampler = Sampler::linear(&ctx, Edge::ClampToEdge).unwrap();
        let points: Vec<[f32; 4]> = (0..16)
            .map(|i| [0.5 + i as f32 * 0.2, 1.5, 2.5, 0.0])
            .collect();
        let input = Buffer::from_slice(&ctx, "points", &points).unwrap();
        let outputs: Vec<Buffer> = (0..2)
            .map(|i| Buffer::new(&ctx, &format!("samples {i}"), 256, Residency::Device).unwrap())
            .collect();
        let bind = || NamedBindings::new(&probe.name, &probe.layout);
        let sampled = (&image, &sampler);

        let unknown = error_of(bind().read("Point", &input));
        assert!(
            unknown.contains("no binding named \"Point\" (its bindings: volume, Points, Samples)"),
            "{unknown}"
        );
        let missing = error_of(bind().read("volume", sampled).read("Points", &input));
        assert!(
            missing.contains("nothing bound to \"Samples\" (binding 2)"),
            "{missing}"
        );
        let kind = error_of(bind().read("volume", &input));
        assert!(
            kind.contains(
                "\"volume\" (binding 0) is a sampled image in the shader; a buffer was given"
            ),
            "{kind}"
        );
        let not_written = error_of(bind().write("Points", &input));
        assert!(
            not_written.contains("only reads \"Points\" (binding 1): bind it with read"),
            "{not_written}"
        );
        let not_read = error_of(bind().read("Samples", &outputs[0]));
        assert!(
            not_read.contains("writes \"Samples\" (binding 2, not readonly): bind it with write"),
            "{not_read}"
        );
        let twice = error_of(bind().read("Points", &input).read("Points", &input));
        assert!(
            twice.contains("\"Points\" (binding 1) is bound twice"),
            "{twice}"
        );

        // Through the recorder the error names the pass and stops the submission.
        let in_submit = ctx
            .submit(|rec| rec.compute(&probe).push(&16u32).dispatch([1, 1, 1]))
            .unwrap_err()
            .to_string();
        assert!(
            in_submit.contains("\"probe\"") && in_submit.contains("nothing bound to \"volume\""),
            "{in_submit}"
        );

        // Named and positional dispatches sample the same values.
        ctx.submit(|rec| {
            rec.compute(&probe)
                .read("Points", &input)
                .write("Samples", &outputs[0])
                .read("volume", sampled)
                .push(&16u32)
                .dispatch([1, 1, 1])?;
            rec.dispatch(
                &probe,
                &[
                    Binding::Sampled(&image, &sampler),
                    Binding::Buffer(&input),
                    Binding::Buffer(&outputs[1]),
                ],
                &16u32,
                [1, 1, 1],
            )
        })
        .unwrap();
        let named: Vec<[f32; 4]> = outputs[0].read(&ctx).unwrap();
        let positional: Vec<[f32; 4]> = outputs[1].read(&ctx).unwrap();
        assert_eq!(named, positional);
        // texel (x, y, z) holds x + 4y + 16z: (0.7, 1.5, 2.5) lies 0.2 past texel (0, 1, 2)
        assert!((named[1][0] - 36.2).abs() < 1e-3, "{:?}", named[1]);
        drop((probe, image, sampler, input, outputs));
        finish(ctx);
    }

    /// A numbered family binds `name0`, `name1`, … (the fragment store's four ranges); a uniform
    /// block refuses a buffer smaller than itself.
    #[test]
    fn families_and_uniform_blocks() {
        let ctx = gpu();
        // glsl/render/splat/tile_count.comp: Fragments0 (0), Counts (1), Fragments1..3 (2..4),
        // the frame's uniform block (5), Field (6).
        let count =
            ComputePipeline::builder("tile count", crate::shaders::RENDER_SPLAT_TILE_COUNT_COMP)
                .build(&ctx)
                .unwrap();
        let buffer = Buffer::new(&ctx, "b", 1024, Residency::Device).unwrap();
        let small = Buffer::new(&ctx, "small", 64, Residency::Upload).unwrap();
        let ranges = |n| -> [Binding<'_>; 4] {
            std::array::from_fn(|k| Binding::BufferRange(&buffer, 256 * (k as u64 % n), 256))
        };
        let bind = || NamedBindings::new(&count.name, &count.layout);
        let bound = bind()
            .read("Fragments", ranges(4))
            .write("Counts", &buffer)
            .read("FrameUniform", &buffer)
            .read("Field", &buffer)
            .finish()
            .unwrap();
        assert_eq!(bound.len(), 7);
        assert!(
            matches!(bound[4], Binding::BufferRange(_, 768, 256)),
            "Fragments3 is binding 4"
        );
        let three = error_of(
            bind()
                .read("Fragments", [ranges(4)[0], ranges(4)[1], ranges(4)[2]])
                .write("Counts", &buffer)
                .read("FrameUniform", &buffer)
                .read("Field", &buffer),
        );
        assert!(
            three.contains("nothing bound to \"Fragments3\" (binding 4)"),
            "{three}"
        );
        let short = error_of(bind().read("FrameUniform", &small));
        assert!(
            short.contains("uniform block \"FrameUniform\" is 88 bytes, buffer \"small\" binds 64"),
            "{short}"
        );
        drop((count, buffer, small));
        finish(ctx);
    }
}
