//! The rasteriser: a scene at one instant → linear HDR colour and metric depth.
//!
//! One render pass draws the scene with 4× MSAA into a colour target (RGBA32F) and a view-depth
//! target (R32F, the distance along the view direction in metres, written per sample). A
//! compute pass (raster.comp) resolves depth to the nearest sample instead of an average, so
//! depth never blends across an edge; asked to ([`Rasterizer::set_mixed_pixels`]), it also
//! writes what lies behind the nearest surface in each pixel's samples (`Frame::rest`). Colour
//! is resolved to the mean of its samples: on a GPU by that compute pass (an H200, which runs
//! graphics on two of its TPCs, drew 4K 5–7 % faster so), on a CPU implementation by the render
//! pass (lavapipe's compute resolve cost more than its render pass saved). Pixels no object
//! covers get the background colour and depth `far_m`.
//! Colour is 32-bit float throughout: values are cd/m², and lamps, the sun and specular
//! emitters exceed half float's 65504 (a half-float target clipped them silently).
//!
//! A frame is either read back (`render`, `render_layers`: inputs for the host) or recorded
//! into another submission and left on the GPU (`scene_frame`, splat's input): both go
//! through the same `prepare` (uniforms through a persistent mapping) and `record`.

use crate::gpu::{
    shader_block, Buffer, ComputePipeline, Context, DepthCompare, Edge, Framebuffer,
    GraphicsPipeline, Image, ImageUsage, Recorder, Residency, Sampler, TexelFormat, Timings,
    VertexAttribute, VertexFormat,
};
use crate::image_io::{ImageGray, ImageRgba};
use crate::scene::{FrameState, Light, Vertex, MAX_LIGHTS};
use crate::{Error, Result};

/// Where the fragment shader evaluates a pixel's surface inputs (position, normal, texture
/// coordinates, depth); glsl/render/raster_shade.glsl says why it matters at silhouettes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceInputs {
    /// Inside the samples the triangle covers (`centroid`): what every frame uses.
    Covered,
    /// At the pixel's centre, inside the triangle or not: extrapolated past silhouettes. The
    /// behaviour before the fix, kept as a negative control for tests.
    PixelCentre,
    /// None: every surface shows its material's reflectance, unlit, at the depth interpolated
    /// inside its samples. A timing diagnostic only (`ocular bench --draw-unshaded`): what the
    /// draw costs without its fragment work; the frame is not the scene's.
    Unshaded,
}

/// Samples per pixel.
pub const MSAA_SAMPLES: u32 = 4;

/// Samples per pixel [`Rasterizer::with_samples`] takes (a device may have fewer).
pub const RASTER_SAMPLE_COUNTS: [u32; 3] = [2, 4, 8];

/// Depth layers a scene is peeled to for splat unless told otherwise (docs/validation.md).
pub const DEFAULT_LAYERS: u32 = 1;

/// Bytes of uniforms a frame sends the device (its only host→device data once the scene is
/// resident).
pub const FRAME_UNIFORM_BYTES: u64 = std::mem::size_of::<FrameUniform>() as u64;

/// A rendered frame on the CPU: row-major, top row first.
#[derive(Clone, Debug)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Linear RGB (luminance Y in cd/m²) and alpha 1.
    pub color: Vec<[f32; 4]>,
    /// Distance along the view direction (camera z), metres.
    pub depth_m: Vec<f32>,
    /// Mixed pixels ([`crate::render::splat::MixedPixels`]): per pixel, rgb the mean colour
    /// of the samples behind the nearest surface's depth group and a that group's share of
    /// the pixel (1 where the pixel shows one surface). Empty for a peeled layer and unless
    /// asked for ([`Rasterizer::set_mixed_pixels`]).
    pub rest: Vec<[f32; 4]>,
    /// The nearest view depth among those samples (m); +∞ where there are none.
    pub rest_depth_m: Vec<f32>,
    /// GPU time per pass ("raster", "resolve", "read back").
    pub timings: Timings,
}

impl Frame {
    pub fn color_image(&self) -> ImageRgba {
        ImageRgba::new(self.width, self.height, self.color.clone())
    }

    pub fn depth_image(&self) -> ImageGray {
        ImageGray::new(self.width, self.height, self.depth_m.clone())
    }

    /// The frame as splat's single-layer input, seen through a `fov_y_deg` vertical field.
    pub fn input(&self, fov_y_deg: f64) -> crate::render::splat::FrameInput<'_> {
        crate::render::splat::FrameInput {
            width: self.width,
            height: self.height,
            color: &self.color,
            depth_m: &self.depth_m,
            fov_y_deg,
            hidden_layers: &[],
            mixed: self.mixed(),
        }
    }

    /// How silhouettes split this frame's pixels between surfaces (None for a peeled layer).
    pub fn mixed(&self) -> Option<crate::render::splat::MixedPixels<'_>> {
        (!self.rest.is_empty()).then_some(crate::render::splat::MixedPixels {
            rest: &self.rest,
            rest_depth_m: &self.rest_depth_m,
        })
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct LightGpu {
    position: [f32; 4],
    rgb: [f32; 4],
}

/// Mirrors `Frame` in glsl/render/raster_frame.glsl (std140: all members 16-byte aligned).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FrameUniform {
    view_proj: [[f32; 4]; 4],
    view: [[f32; 4]; 4],
    camera_position: [f32; 4],
    ambient: [f32; 4],
    counts: [u32; 4],
    lights: [LightGpu; MAX_LIGHTS],
}

shader_block! {
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    struct MaterialPush {
        albedo: [f32; 4],
        emission: [f32; 4],
        /// x, y: the nearest and farthest view depth (m) of the batch's box within the clip range
        /// (see raster_shade.glsl).
        depth_range_m: [f32; 4],
    }
}

shader_block! {
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    struct ResolvePush {
        width: u32,
        height: u32,
        samples: u32,
        /// 1: also write the rest of mixed pixels (the visible layer); 0: depth only.
        split: u32,
        group_tolerance_d: f32,
        /// 1: also write the colour's mean (a GPU's resolve); 0: the render pass resolved it.
        colour: u32,
    }
}

/// Scene data uploaded once and reused while the same scene is rendered.
struct GpuScene {
    scene_id: u64,
    vertices: Buffer,
    indices: Buffer,
    textures: Vec<Image>,
}

/// Render targets for one frame size.
struct Targets {
    width: u32,
    height: u32,
    /// Whether `rest` and `rest_depth` hold a frame (made so when mixed pixels are asked for).
    mixed_pixels: bool,
    /// Whether `color_ms` can be sampled (the compute resolve reads it).
    colour_read: bool,
    color_ms: Image,
    depth_ms: Image,
    /// View depth per sample of layer 0 and every even layer.
    view_depth_ms: Image,
    color: Image,
    framebuffer: Framebuffer,
    /// What peeling adds, made at the first peel (a frame of one layer needs none).
    peel: Option<PeelTargets>,
    /// The resolved depth (view-axis metres, row-major), on the device.
    depth: Buffer,
    /// The rest of mixed pixels (raster.comp's `Rest`, `RestDepth`), on the device.
    rest: Buffer,
    rest_depth: Buffer,
    /// Persistent read-back buffers (colour, depth, rest, rest depth) of the host path
    /// (`render`, `render_layers`), made at its first frame: a frame that stays on the GPU
    /// needs none.
    readback: Option<[Buffer; 4]>,
}

/// Layer k is drawn into the view depth of its parity (`Targets::view_depth_ms` for even k, the
/// odd one here), and the peel that draws layer k + 1 reads layer k's samples from the other.
struct PeelTargets {
    odd_view_depth_ms: Image,
    /// The peeling pipeline's targets drawing into the even and the odd view depth.
    framebuffers: [Framebuffer; 2],
}

impl Targets {
    /// The view depth layer `layer` is drawn into.
    fn view_depth(&self, layer: u32) -> &Image {
        match (&self.peel, layer % 2) {
            (Some(peel), 1) => &peel.odd_view_depth_ms,
            _ => &self.view_depth_ms,
        }
    }
}

pub struct Rasterizer {
    pipeline: GraphicsPipeline,
    peel: GraphicsPipeline,
    resolve: ComputePipeline,
    texture_sampler: Sampler,
    point_sampler: Sampler,
    white: Image,
    scene: Option<GpuScene>,
    targets: Option<Targets>,
    /// The frame's uniforms, written through the mapping before each frame's submission.
    uniforms: Buffer,
    /// How directions in front of the eye appear (view-space x, y: +x right, +y up): the
    /// angular magnification of a spectacle lens, identity without one.
    view_magnification: [[f64; 2]; 2],
    /// Whether the visible layer's resolve also writes its mixed pixels (`Frame::rest`).
    mixed_pixels: bool,
    /// Samples per pixel ([`MSAA_SAMPLES`] but for the draw's timing diagnostic).
    samples: u32,
    /// Whether colour is resolved in compute (raster.comp) rather than by the render pass:
    /// on GPUs (see the module's header).
    colour_in_compute: bool,
    /// The multisampled colour in half floats ([`Self::for_diagnostic`] only).
    half_colour: bool,
}

/// The multisampled colour's format: single floats, or half ones for the draw's diagnostic.
fn colour_format(half: bool) -> TexelFormat {
    if half {
        TexelFormat::Rgba16Float
    } else {
        TexelFormat::Rgba32Float
    }
}

impl Rasterizer {
    pub fn new(ctx: &Context) -> Result<Rasterizer> {
        Self::with_inputs(ctx, SurfaceInputs::Covered)
    }

    /// A rasteriser whose first layer interpolates the surface inputs as `inputs` says. Only
    /// [`SurfaceInputs::Covered`] renders correctly; the other exists as the silhouette test's
    /// negative control.
    pub fn with_inputs(ctx: &Context, inputs: SurfaceInputs) -> Result<Rasterizer> {
        Self::with_samples(ctx, inputs, MSAA_SAMPLES)
    }

    /// As [`Self::with_inputs`], with `samples` per pixel (2, 4 or 8) where every frame uses
    /// [`MSAA_SAMPLES`]: a timing diagnostic (`ocular bench --draw-samples`), since coverage
    /// and mixed pixels are only as fine as the samples.
    pub fn with_samples(ctx: &Context, inputs: SurfaceInputs, samples: u32) -> Result<Rasterizer> {
        Self::for_diagnostic(ctx, inputs, samples, false)
    }

    /// As [`Self::with_samples`], and with `half_colour` the multisampled colour in half
    /// floats (8 bytes a sample where every frame writes 16), resolved in compute on any
    /// device: a timing diagnostic (`ocular bench --draw-half-colour`) of how the draw follows
    /// the bytes it writes. Values over 65504 cd/m² clip, so no frame is drawn so.
    pub fn for_diagnostic(
        ctx: &Context,
        inputs: SurfaceInputs,
        samples: u32,
        half_colour: bool,
    ) -> Result<Rasterizer> {
        let on_gpu = ctx.device_info().kind != crate::gpu::DeviceKind::Cpu;
        let mut r = Self::build(ctx, inputs, samples, on_gpu || half_colour, half_colour)?;
        r.half_colour = half_colour;
        Ok(r)
    }

    /// A rasteriser that resolves colour in compute (`true`) or by the render pass, whatever
    /// the device: the two give the same frames (`tests/it/raster.rs` holds them to it on
    /// lavapipe, where [`Self::new`] resolves by the render pass).
    pub fn with_colour_resolve(ctx: &Context, in_compute: bool) -> Result<Rasterizer> {
        Self::build(ctx, SurfaceInputs::Covered, MSAA_SAMPLES, in_compute, false)
    }

    fn build(
        ctx: &Context,
        inputs: SurfaceInputs,
        samples: u32,
        colour_in_compute: bool,
        half_colour: bool,
    ) -> Result<Rasterizer> {
        if !RASTER_SAMPLE_COUNTS.contains(&samples) {
            return Err(crate::Error::input(format!(
                "raster samples per pixel: {samples}; allowed: 2, 4 or 8"
            )));
        }
        let draw = (samples, colour_in_compute, half_colour);
        let pipeline = Self::pipeline(ctx, false, inputs, draw)?;
        let peel = Self::pipeline(ctx, true, SurfaceInputs::Covered, draw)?;
        let resolve = ComputePipeline::builder("resolve", crate::shaders::RENDER_RASTER_COMP)
            .push_constants::<ResolvePush>()
            .build(ctx)?;
        let white = Image::new_2d(
            ctx,
            "white texture",
            1,
            1,
            TexelFormat::Rgba8Srgb,
            ImageUsage::SAMPLED,
        )?;
        white.upload(ctx, &[[255u8; 4]])?;
        Ok(Rasterizer {
            pipeline,
            peel,
            resolve,
            texture_sampler: Sampler::linear(ctx, Edge::Repeat)?,
            point_sampler: Sampler::linear(ctx, Edge::ClampToEdge)?,
            white,
            scene: None,
            targets: None,
            uniforms: Buffer::new(
                ctx,
                "raster frame uniforms",
                std::mem::size_of::<FrameUniform>() as u64,
                Residency::Upload,
            )?,
            view_magnification: [[1.0, 0.0], [0.0, 1.0]],
            mixed_pixels: false,
            samples,
            colour_in_compute,
            half_colour,
        })
    }

    /// The raster pipeline, or its depth-peeling variant (one more binding: the previous
    /// layer's samples, `previous_samples` in glsl/render/raster_peel.frag), with `samples`
    /// per pixel, its colour resolved by the render pass unless `colour_in_compute`, and in
    /// half floats with `half_colour` (a diagnostic: [`Self::for_diagnostic`]).
    fn pipeline(
        ctx: &Context,
        peel: bool,
        inputs: SurfaceInputs,
        (samples, colour_in_compute, half_colour): (u32, bool, bool),
    ) -> Result<GraphicsPipeline> {
        let stride = std::mem::size_of::<Vertex>() as u32;
        let (name, fragment) = match (peel, inputs) {
            (true, _) => ("raster peel", crate::shaders::RENDER_RASTER_PEEL_FRAG),
            (false, SurfaceInputs::Covered) => ("raster", crate::shaders::RENDER_RASTER_FRAG),
            (false, SurfaceInputs::PixelCentre) => (
                "raster (pixel-centre inputs)",
                crate::shaders::RENDER_RASTER_CENTRE_FRAG,
            ),
            (false, SurfaceInputs::Unshaded) => (
                "raster (unshaded)",
                crate::shaders::RENDER_RASTER_UNSHADED_FRAG,
            ),
        };
        Ok(
            GraphicsPipeline::builder(name, crate::shaders::RENDER_RASTER_VERT, fragment)
                .vertex_layout(
                    stride,
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
                        VertexAttribute {
                            location: 3,
                            format: VertexFormat::Float,
                            offset: 32,
                        },
                    ],
                )
                .push_constants::<MaterialPush>()
                .samples(samples)
                .color_target(colour_format(half_colour), !colour_in_compute)
                .color_target(TexelFormat::R32Float, false)
                .depth_target(TexelFormat::D32Float, DepthCompare::Greater)
                .build(ctx)?,
        )
    }

    fn upload_scene(&mut self, ctx: &Context, state: &FrameState<'_>) -> Result<()> {
        let scene = state.scene;
        if self.scene.as_ref().map(|s| s.scene_id) == Some(scene.id()) {
            return Ok(());
        }
        self.scene = None;
        let g = &scene.geometry;
        let vertices = if g.vertices.is_empty() {
            Buffer::new(ctx, "scene vertices", 16, Residency::Device)?
        } else {
            Buffer::from_slice(ctx, "scene vertices", &g.vertices)?
        };
        let indices = if g.indices.is_empty() {
            Buffer::new(ctx, "scene indices", 16, Residency::Device)?
        } else {
            Buffer::from_slice(ctx, "scene indices", &g.indices)?
        };
        let mut textures = Vec::with_capacity(g.textures.len());
        for t in &g.textures {
            let image = Image::new_2d(
                ctx,
                &t.source,
                t.width,
                t.height,
                TexelFormat::Rgba8Srgb,
                ImageUsage::SAMPLED,
            )?;
            image.upload(ctx, &t.rgba8_srgb)?;
            textures.push(image);
        }
        self.scene = Some(GpuScene {
            scene_id: scene.id(),
            vertices,
            indices,
            textures,
        });
        Ok(())
    }

    fn ensure_targets(&mut self, ctx: &Context, width: u32, height: u32) -> Result<()> {
        if self.targets.as_ref().is_some_and(|t| {
            t.width == width && t.height == height && t.mixed_pixels == self.mixed_pixels
        }) {
            return Ok(());
        }
        self.targets = None;
        let attachment = |depth: bool, sampled: bool, samples: u32| ImageUsage {
            sampled_linear: sampled,
            storage: false,
            color_attachment: !depth,
            depth_attachment: depth,
            samples,
        };
        // every target is a width × height image
        let target = |name: &str, format: TexelFormat, usage: ImageUsage| {
            Image::new_2d(ctx, name, width, height, format, usage)
        };
        // sampled only where the compute resolve reads its samples (raster.comp): a sampled
        // attachment may lose a GPU's colour compression
        let colour_read = self.colour_in_compute || self.mixed_pixels;
        let color_ms = target(
            "raster colour (MSAA)",
            colour_format(self.half_colour),
            attachment(false, colour_read, self.samples),
        )?;
        let view_depth_ms = target(
            "raster view depth (MSAA)",
            TexelFormat::R32Float,
            attachment(false, true, self.samples),
        )?;
        let depth_ms = target(
            "raster depth buffer (MSAA)",
            TexelFormat::D32Float,
            attachment(true, false, self.samples),
        )?;
        // storage: the resolve writes it, and splat's input pass reads it where the frame
        // stays on the GPU
        let color = target(
            "raster colour",
            TexelFormat::Rgba32Float,
            ImageUsage {
                storage: true,
                color_attachment: !self.colour_in_compute,
                ..attachment(false, false, 1)
            },
        )?;
        let resolves: &[&Image] = if self.colour_in_compute {
            &[]
        } else {
            &[&color]
        };
        let framebuffer = self.pipeline.framebuffer(
            ctx,
            &[&color_ms, &view_depth_ms],
            resolves,
            Some(&depth_ms),
        )?;
        let pixels = u64::from(width) * u64::from(height);
        self.targets = Some(Targets {
            depth: Buffer::new(ctx, "raster depth", pixels * 4, Residency::Device)?,
            // a frame's worth only where mixed pixels are asked for (133 MB at 4K); else a
            // placeholder the resolve binds and never writes
            rest: Buffer::new(
                ctx,
                "raster mixed-pixel rest",
                if self.mixed_pixels { pixels * 16 } else { 16 },
                Residency::Device,
            )?,
            rest_depth: Buffer::new(
                ctx,
                "raster mixed-pixel rest depth",
                if self.mixed_pixels { pixels * 4 } else { 16 },
                Residency::Device,
            )?,
            readback: None,
            width,
            height,
            peel: None,
            mixed_pixels: self.mixed_pixels,
            colour_read,
            color_ms,
            depth_ms,
            view_depth_ms,
            color,
            framebuffer,
        });
        Ok(())
    }

    /// The second view depth and the peeling framebuffers of this size, made once.
    fn ensure_peel_targets(&mut self, ctx: &Context) -> Result<()> {
        let targets = self.targets.as_mut().expect("made first");
        if targets.peel.is_some() {
            return Ok(());
        }
        let odd_view_depth_ms = Image::new_2d(
            ctx,
            "raster view depth (MSAA, odd layers)",
            targets.width,
            targets.height,
            TexelFormat::R32Float,
            ImageUsage {
                sampled_linear: true,
                storage: false,
                color_attachment: true,
                depth_attachment: false,
                samples: self.samples,
            },
        )?;
        let resolves: &[&Image] = if self.colour_in_compute {
            &[]
        } else {
            &[&targets.color]
        };
        let framebuffer = |view_depth: &Image| {
            self.peel.framebuffer(
                ctx,
                &[&targets.color_ms, view_depth],
                resolves,
                Some(&targets.depth_ms),
            )
        };
        let framebuffers = [
            framebuffer(&targets.view_depth_ms)?,
            framebuffer(&odd_view_depth_ms)?,
        ];
        targets.peel = Some(PeelTargets {
            odd_view_depth_ms,
            framebuffers,
        });
        Ok(())
    }

    /// Draws every later frame as seen through an optical element that maps a direction's
    /// tangents t to `m`·t (view space, +x right, +y up), such as a spectacle lens's angular
    /// magnification ([`crate::eye::correction::Spectacle::angular_magnification`]). Depth
    /// stays the distance along the camera's view axis: the element moves images, not objects.
    pub fn set_view_magnification(&mut self, m: [[f64; 2]; 2]) {
        self.view_magnification = m;
    }

    /// Whether later frames read back their mixed pixels ([`Frame::rest`]): what lies behind
    /// the nearest surface's depth group in each pixel's samples. Off by default: only the
    /// comparison's `--edge-pixels split` reads them (docs/validation.md, "Mixed pixels").
    pub fn set_mixed_pixels(&mut self, on: bool) {
        self.mixed_pixels = on;
    }

    /// World → clip of `camera` for this frame, with the view magnification.
    fn view_projection(&self, camera: &crate::scene::Camera, aspect: f64) -> glam::DMat4 {
        let m = self.view_magnification;
        let magnify = glam::DMat4::from_cols(
            glam::DVec4::new(m[0][0], m[1][0], 0.0, 0.0),
            glam::DVec4::new(m[0][1], m[1][1], 0.0, 0.0),
            glam::DVec4::Z,
            glam::DVec4::W,
        );
        camera.projection_matrix(aspect) * magnify * camera.view_matrix()
    }

    /// Renders `state` at `width × height` and reads colour and depth back.
    pub fn render(
        &mut self,
        ctx: &Context,
        state: &FrameState<'_>,
        width: u32,
        height: u32,
    ) -> Result<Frame> {
        let camera = &state.camera;
        let view_proj = self.view_projection(camera, f64::from(width) / f64::from(height));
        self.render_from(ctx, state, width, height, view_proj, camera.position_m)
    }

    /// Renders `state` through `view_proj` (world → clip) seen from `eye_position_m` (where
    /// view-dependent shading looks from), e.g. an off-axis frustum from a point on the pupil.
    /// Depth stays the distance along the camera's own view axis.
    pub fn render_from(
        &mut self,
        ctx: &Context,
        state: &FrameState<'_>,
        width: u32,
        height: u32,
        view_proj: glam::DMat4,
        eye_position_m: [f64; 3],
    ) -> Result<Frame> {
        self.draw(ctx, state, (width, height), view_proj, eye_position_m, None)
    }

    /// The first `layers` surfaces along each pixel's ray (depth peeling), nearest first.
    /// Layer 0 is [`Rasterizer::render`]'s frame; in the others a pixel with no surface has
    /// colour 0 and depth +∞, and a surface lies behind the previous layer's by more than
    /// `gap_d` dioptres (the blend's depth-group tolerance) and faces the eye, sample by
    /// sample. Edge pixels hold the hidden surface's own colour (coverage divided out).
    pub fn render_layers(
        &mut self,
        ctx: &Context,
        state: &FrameState<'_>,
        (width, height): (u32, u32),
        layers: u32,
        gap_d: f32,
    ) -> Result<Vec<Frame>> {
        let camera = &state.camera;
        let view_proj = self.view_projection(camera, f64::from(width) / f64::from(height));
        let mut frames = vec![self.render(ctx, state, width, height)?];
        let far = camera.far_m as f32;
        for layer in 1..layers {
            let mut frame = self.draw(
                ctx,
                state,
                (width, height),
                view_proj,
                camera.position_m,
                Some((layer, gap_d)),
            )?;
            for (c, d) in frame.color.iter_mut().zip(frame.depth_m.iter_mut()) {
                if c[3] > 1e-6 && *d < far {
                    *c = [c[0] / c[3], c[1] / c[3], c[2] / c[3], 1.0];
                } else {
                    *c = [0.0; 4];
                    *d = f32::INFINITY;
                }
            }
            frames.push(frame);
        }
        Ok(frames)
    }

    fn draw(
        &mut self,
        ctx: &Context,
        state: &FrameState<'_>,
        (width, height): (u32, u32),
        view_proj: glam::DMat4,
        eye_position_m: [f64; 3],
        peel: Option<(u32, f32)>,
    ) -> Result<Frame> {
        let gap_d = peel.map(|(_, gap)| gap);
        self.prepare(
            ctx,
            state,
            (width, height),
            view_proj,
            eye_position_m,
            gap_d,
        )?;
        let targets = self.targets.as_mut().expect("prepared");
        if targets.readback.is_none() {
            let pixels = u64::from(width) * u64::from(height);
            let readback = |name: &str, bytes: u64| {
                Buffer::new(ctx, name, pixels * bytes, Residency::Readback)
            };
            // the rest's read-backs hold a frame only where mixed pixels are asked for
            let rest_pixels = if targets.mixed_pixels { 1 } else { 0 };
            targets.readback = Some([
                readback("raster colour read-back", 16)?,
                readback("raster depth read-back", 4)?,
                Buffer::new(
                    ctx,
                    "raster rest read-back",
                    (pixels * 16 * rest_pixels).max(16),
                    Residency::Readback,
                )?,
                Buffer::new(
                    ctx,
                    "raster rest depth read-back",
                    (pixels * 4 * rest_pixels).max(16),
                    Residency::Readback,
                )?,
            ]);
        }
        let targets = self.targets.as_ref().expect("prepared");
        let [color_readback, depth_readback, rest_readback, rest_depth_readback] =
            targets.readback.as_ref().expect("made above");
        let layer = peel.map_or(0, |(layer, _)| layer);
        let timings = ctx.submit(|rec| {
            self.record(rec, state, layer)?;
            rec.begin_pass("read back");
            rec.copy_image_to_buffer(&targets.color, color_readback);
            rec.copy_buffer(&targets.depth, depth_readback, targets.depth.size_bytes());
            if layer == 0 && self.mixed_pixels {
                rec.copy_buffer(&targets.rest, rest_readback, targets.rest.size_bytes());
                rec.copy_buffer(
                    &targets.rest_depth,
                    rest_depth_readback,
                    targets.rest_depth.size_bytes(),
                );
            }
            Ok(())
        })?;
        let pixels = width as usize * height as usize;
        let (rest, rest_depth_m) = if layer == 0 && self.mixed_pixels {
            (
                rest_readback.read_mapped(0, pixels)?,
                rest_depth_readback.read_mapped(0, pixels)?,
            )
        } else {
            (Vec::new(), Vec::new())
        };
        Ok(Frame {
            width,
            height,
            color: color_readback.read_mapped(0, pixels)?,
            depth_m: depth_readback.read_mapped(0, pixels)?,
            rest,
            rest_depth_m,
            timings,
        })
    }

    /// Everything a frame needs before its commands are recorded: the scene on the GPU,
    /// targets of this size and the frame's uniforms (written through their mapping).
    fn prepare(
        &mut self,
        ctx: &Context,
        state: &FrameState<'_>,
        (width, height): (u32, u32),
        view_proj: glam::DMat4,
        eye_position_m: [f64; 3],
        peel_gap_d: Option<f32>,
    ) -> Result<()> {
        if width == 0 || height == 0 {
            return Err(Error::input(format!(
                "frame size {width}×{height} has no pixels"
            )));
        }
        self.upload_scene(ctx, state)?;
        self.ensure_targets(ctx, width, height)?;
        if peel_gap_d.is_some() {
            self.ensure_peel_targets(ctx)?;
        }
        let mut uniform = FrameUniform {
            view_proj: view_proj.as_mat4().to_cols_array_2d(),
            view: state.camera.view_matrix().as_mat4().to_cols_array_2d(),
            camera_position: [
                eye_position_m[0] as f32,
                eye_position_m[1] as f32,
                eye_position_m[2] as f32,
                1.0,
            ],
            ambient: [0.0; 4],
            counts: [0; 4],
            lights: [LightGpu {
                position: [0.0; 4],
                rgb: [0.0; 4],
            }; MAX_LIGHTS],
        };
        let mut count = 0usize;
        for light in &state.scene.lights {
            match *light {
                Light::Ambient { rgb_lux } => {
                    for (sum, add) in uniform.ambient.iter_mut().zip(rgb_lux) {
                        *sum += add;
                    }
                }
                Light::Directional { direction, rgb_lux } => {
                    uniform.lights[count] = LightGpu {
                        position: [direction[0], direction[1], direction[2], 0.0],
                        rgb: [rgb_lux[0], rgb_lux[1], rgb_lux[2], 0.0],
                    };
                    count += 1;
                }
                Light::Point { position_m, rgb_cd } => {
                    uniform.lights[count] = LightGpu {
                        position: [position_m[0], position_m[1], position_m[2], 1.0],
                        rgb: [rgb_cd[0], rgb_cd[1], rgb_cd[2], 0.0],
                    };
                    count += 1;
                }
            }
        }
        uniform.counts[0] = count as u32;
        // the peeling shader reads its gap from the otherwise unused ambient.w
        if let Some(gap_d) = peel_gap_d {
            uniform.ambient[3] = gap_d;
        }
        self.uniforms
            .write_mapped(0, std::slice::from_ref(&uniform))?;
        Ok(())
    }

    /// Records the prepared frame's draw and resolve: colour in `targets.color`, depth
    /// in `targets.depth`.
    fn record(
        &self,
        rec: &mut Recorder<'_>,
        state: &FrameState<'_>,
        layer: u32,
    ) -> crate::gpu::GpuResult<()> {
        let gpu_scene = self.scene.as_ref().expect("prepared");
        let targets = self.targets.as_ref().expect("prepared");
        let (width, height) = (targets.width, targets.height);
        let bg = state.scene.background_rgb;
        let peel = layer > 0;
        let (pipeline, framebuffer, clear) = if peel {
            let framebuffers = &targets.peel.as_ref().expect("made by prepare").framebuffers;
            (&self.peel, &framebuffers[(layer % 2) as usize], [0.0; 4])
        } else {
            (
                &self.pipeline,
                &targets.framebuffer,
                [bg[0], bg[1], bg[2], 1.0],
            )
        };
        let far = state.camera.far_m as f32;
        let (eye_m, forward) = (state.camera.position_m, state.camera.forward());
        let (clip_near_m, clip_far_m) = (state.camera.near_m, state.camera.far_m);
        let materials = &state.scene.geometry.materials;
        rec.begin_pass("raster");
        rec.begin_render_pass(pipeline, framebuffer, &[clear, [far, 0.0, 0.0, 0.0]], 0.0)?;
        for batch in &state.scene.geometry.batches {
            let material = &materials[batch.material];
            let texture = material
                .texture
                .and_then(|t| gpu_scene.textures.get(t))
                .unwrap_or(&self.white);
            let push = MaterialPush {
                albedo: [
                    material.albedo[0],
                    material.albedo[1],
                    material.albedo[2],
                    if material.texture.is_some() { 1.0 } else { 0.0 },
                ],
                emission: [
                    material.emission[0],
                    material.emission[1],
                    material.emission[2],
                    0.0,
                ],
                depth_range_m: {
                    let (lo, hi) = batch.view_depth_range_m(eye_m, forward);
                    // clipping keeps every fragment inside [near, far]
                    let lo = lo.max(clip_near_m);
                    let hi = hi.min(clip_far_m).max(lo);
                    [lo as f32, hi as f32, 0.0, 0.0]
                },
            };
            let mut bound = pipeline
                .bind()
                .read("Frame", &self.uniforms)
                .read("albedo_map", (texture, &self.texture_sampler));
            if peel {
                bound = bound.read(
                    "previous_samples",
                    (targets.view_depth(layer - 1), &self.point_sampler),
                );
            }
            rec.draw_indexed(
                pipeline,
                &bound.finish()?,
                &push,
                &gpu_scene.vertices,
                &gpu_scene.indices,
                batch.first_index,
                batch.index_count,
            )?;
        }
        rec.end_render_pass()?;
        rec.begin_pass("resolve");
        rec.compute(&self.resolve)
            .read(
                "view_depth",
                (targets.view_depth(layer), &self.point_sampler),
            )
            .write("Depth", &targets.depth)
            // where the shader reads no colour sample, any multisampled image that can be
            // sampled stands in
            .read(
                "color_samples",
                (
                    if targets.colour_read {
                        &targets.color_ms
                    } else {
                        targets.view_depth(layer)
                    },
                    &self.point_sampler,
                ),
            )
            .write("color_out", &targets.color)
            .write("Rest", &targets.rest)
            .write("RestDepth", &targets.rest_depth)
            .push(&ResolvePush {
                width,
                height,
                samples: self.samples,
                split: u32::from(layer == 0 && self.mixed_pixels),
                group_tolerance_d: crate::render::blend::DEFAULT_GROUP_TOLERANCE_D,
                colour: u32::from(self.colour_in_compute),
            })
            .dispatch([width.div_ceil(8), height.div_ceil(8), 1])?;
        // The MSAA depth buffer lives as long as the framebuffers that use it.
        let _ = &targets.depth_ms;
        Ok(())
    }

    /// Prepares `state`'s frame, seen by its own camera at `width`×`height`, for recording
    /// into another submission (with the peeling gap where layers follow: the raster shader
    /// ignores it, so layer 0 is the same either way); returns the bytes it wrote for the
    /// device.
    pub(crate) fn prepare_camera_frame(
        &mut self,
        ctx: &Context,
        state: &FrameState<'_>,
        (width, height): (u32, u32),
        peel_gap_d: Option<f32>,
    ) -> Result<u64> {
        let camera = &state.camera;
        let aspect = f64::from(width) / f64::from(height);
        let view_proj = self.view_projection(camera, aspect);
        self.prepare(
            ctx,
            state,
            (width, height),
            view_proj,
            camera.position_m,
            peel_gap_d,
        )?;
        Ok(FRAME_UNIFORM_BYTES)
    }

    /// Records the prepared frame's draw (`layer` 0), or the next layer's, peeled behind the
    /// samples of the layer before, which the same submission drew; returns where it leaves
    /// the layer.
    pub(crate) fn record_frame(
        &self,
        rec: &mut Recorder<'_>,
        state: &FrameState<'_>,
        layer: u32,
    ) -> crate::gpu::GpuResult<crate::render::splat::RecordedLayer<'_>> {
        self.record(rec, state, layer)?;
        let targets = self.targets.as_ref().expect("prepared");
        Ok(crate::render::splat::RecordedLayer {
            color: &targets.color,
            depth_m: &targets.depth,
            far_m: state.camera.far_m as f32,
        })
    }
}
