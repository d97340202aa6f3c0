//! Where a frame's colour and depth come from. A host frame (EXR, PNG, layered inputs) is
//! written into persistent mapped staging buffers and copied into splat's input images; a
//! frame the GPU makes itself (a rasterised scene, [`RecordedInput`]) is recorded into splat's
//! own submission and taken into the input images by the input pass (glsl/render/splat/
//! input.comp), so its pixels never cross to the host. A peeled frame is recorded layer by
//! layer, each draw followed by the input pass that stacks it under the earlier ones and
//! hands its depth to the next peel on the GPU. Both feed the same passes after this.

use crate::gpu::{
    shader_block, Buffer, Context, GpuResult, Image, Recorder, Residency,
};
use crate::{Error, Result};

use super::{FrameInput, FrameResources};

/// A frame made on the GPU inside splat's submission, as one or more depth layers.
pub trait RecordedInput {
    /// Width and height in pixels.
    fn size(&self) -> (u32, u32);
    /// Depth layers the frame has: 1, the visible surface, unless the frame is peeled.
    fn layers(&self) -> u32 {
        1
    }
    /// Vertical field of view of the pinhole camera that makes the frame (degrees).
    fn fov_y_deg(&self) -> f64;
    /// Host-side work before recording (uploads, uniforms through their mapping); returns the
    /// bytes it wrote for the device.
    fn prepare(&mut self) -> Result<u64>;
    /// Records the commands that make layer `layer` (0: the visible surface; layer k is
    /// recorded after the input pass took layer k − 1, whose samples it peels behind) and
    /// returns where they leave it.
    fn record_layer<'a>(
        &'a self,
        rec: &mut Recorder<'_>,
        layer: u32,
    ) -> GpuResult<RecordedLayer<'a>>;
}

/// Where a recorded layer's commands leave it.
pub struct RecordedLayer<'a> {
    /// Linear RGB in an RGBA32F image with storage usage; in a hidden layer, premultiplied by
    /// the coverage in alpha.
    pub color: &'a Image,
    /// The distance along the view axis in metres, one f32 per pixel, row-major.
    pub depth_m: &'a Buffer,
    /// Distance at and beyond which a pixel shows no surface (the far plane, metres).
    pub far_m: f32,
}

pub(super) enum Source<'i, 'f> {
    Host(&'i FrameInput<'f>),
    Gpu(&'i mut dyn RecordedInput),
}

/// What splat needs to know about a frame before it runs.
pub(super) struct Shape {
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    pub fov_y_deg: f64,
}

/// Persistent, mapped staging buffers for host frames: colour, then depth, layer under layer.
pub(super) struct Staging {
    color: Buffer,
    depth: Buffer,
}

shader_block! {
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    pub(super) struct InputPush {
        pub width: u32,
        pub height: u32,
        /// Which layer of the stack this dispatch writes (its rows start at layer · height).
        pub layer: u32,
        pub near_m: f32,
        pub far_m: f32,
    }
}

super::passes::compute_pass!(InputPass, "input", RENDER_SPLAT_INPUT_COMP, push: InputPush);

impl Source<'_, '_> {
    /// The frame's size, layers and field, after checking that its parts agree.
    pub fn shape(&self) -> Result<Shape> {
        let shape = match self {
            Source::Gpu(frame) => {
                let (width, height) = frame.size();
                Shape {
                    width,
                    height,
                    layers: frame.layers(),
                    fov_y_deg: frame.fov_y_deg(),
                }
            }
            Source::Host(input) => {
                let (w, h) = (input.width, input.height);
                let pixels = w as usize * h as usize;
                if w == 0 || h == 0 || input.color.len() != pixels || input.depth_m.len() != pixels
                {
                    return Err(Error::input(format!(
                        "frame of {w}×{h} needs {pixels} colour and depth values (got {} and {})",
                        input.color.len(),
                        input.depth_m.len()
                    )));
                }
                for (k, layer) in input.hidden_layers.iter().enumerate() {
                    if layer.color.len() != pixels || layer.depth_m.len() != pixels {
                        return Err(Error::input(format!(
                            "hidden layer {} of a {w}×{h} frame needs {pixels} colour and depth \
                             values (got {} and {})",
                            k + 1,
                            layer.color.len(),
                            layer.depth_m.len()
                        )));
                    }
                }
                Shape {
                    width: w,
                    height: h,
                    layers: 1 + input.hidden_layers.len() as u32,
                    fov_y_deg: input.fov_y_deg,
                }
            }
        };
        if shape.layers == 0 {
            return Err(Error::input("a frame needs at least one depth layer"));
        }
        if shape.width == 0 || shape.height == 0 {
            return Err(Error::input(format!(
                "frame size {}×{} has no pixels",
                shape.width, shape.height
            )));
        }
        crate::limits::FOV_Y_DEG
            .check("vertical field of view", shape.fov_y_deg)
            .map_err(Error::input)?;
        Ok(shape)
    }

    /// Host-side work for the frame: a host frame goes into the staging buffers (made at the
    /// first host frame of this size), a GPU frame prepares itself. Returns the bytes written
    /// for the device.
    pub fn stage(&mut self, ctx: &Context, frame: &mut FrameResources) -> Result<u64> {
        let input = match self {
            Source::Gpu(recorded) => return recorded.prepare(),
            Source::Host(input) => input,
        };
        let pixels = frame.width as usize * frame.height as usize;
        if frame.staging.is_none() {
            let texels = (pixels * frame.layers as usize) as u64;
            frame.staging = Some(Staging {
                color: Buffer::new(ctx, "input colour staging", texels * 16, Residency::Upload)?,
                depth: Buffer::new(ctx, "input depth staging", texels * 4, Residency::Upload)?,
            });
        }
        let staging = frame.staging.as_mut().expect("made above");
        staging.color.write_mapped(0, input.color)?;
        staging.depth.write_mapped(0, input.depth_m)?;
        for (k, layer) in input.hidden_layers.iter().enumerate() {
            staging.color.write_mapped((k + 1) * pixels, layer.color)?;
            staging
                .depth
                .write_mapped((k + 1) * pixels, layer.depth_m)?;
        }
        Ok((pixels * 20 * frame.layers as usize) as u64)
    }

    /// Records what leaves the frame in `frame.color_in` and `frame.depth_in`.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        pass: &InputPass,
        frame: &FrameResources,
    ) -> GpuResult<()> {
        match self {
            Source::Host(_) => {
                let staging = frame.staging.as_ref().expect("staged before recording");
                rec.begin_pass("upload");
                rec.copy_buffer_to_image(&staging.color, &frame.color_in);
                rec.copy_buffer_to_image(&staging.depth, &frame.depth_in);
                Ok(())
            }
            Source::Gpu(recorded) => {
                let layers = recorded.layers();
                for layer in 0..layers {
                    let out = recorded.record_layer(rec, layer)?;
                    rec.begin_pass("input");
                    rec.compute(&pass.pipeline)
                        .read("raster_color", out.color)
                        .read("RasterDepth", out.depth_m)
                        .write("color_in", &frame.color_in)
                        .write("depth_in", &frame.depth_in)
                        .push(&InputPush {
                            width: frame.width,
                            height: frame.height,
                            layer,
                            near_m: crate::render::focus::nearest_supported_m(),
                            far_m: out.far_m,
                        })
                        .dispatch([frame.width.div_ceil(8), frame.height.div_ceil(8), 1])?;
                }
                Ok(())
            }
        }
    }
}
