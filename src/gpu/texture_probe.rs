//! Samples a 3D image through a sampler at arbitrary points on the GPU and reads the values
//! back: what a shader sees, for comparison with CPU references.

use super::{shader_block, Buffer, ComputePipeline, Context, GpuResult, Image, Residency, Sampler};

shader_block! {
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    struct Push {
        count: u32,
    }
}

pub struct TextureProbe {
    pipeline: ComputePipeline,
}

impl TextureProbe {
    pub fn new(ctx: &Context) -> GpuResult<TextureProbe> {
        let pipeline =
            ComputePipeline::builder("texture probe", crate::shaders::GPU_TEXTURE_PROBE_COMP)
                .push_constants::<Push>()
                .build(ctx)?;
        Ok(TextureProbe { pipeline })
    }

    /// Samples `image` through `sampler` at texel-space `points` (texel centres at i + 0.5).
    pub fn sample(
        &self,
        ctx: &Context,
        image: &Image,
        sampler: &Sampler,
        points: &[[f32; 3]],
    ) -> GpuResult<Vec<[f32; 4]>> {
        let padded: Vec<[f32; 4]> = points.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect();
        let input = Buffer::from_slice(ctx, "probe points", &padded)?;
        let output = Buffer::new(
            ctx,
            "probe samples",
            (points.len() * 16) as u64,
            Residency::Device,
        )?;
        let groups = (points.len() as u32).div_ceil(64).clamp(1, 65_535);
        ctx.submit(|rec| {
            rec.begin_pass("texture probe");
            rec.compute(&self.pipeline)
                .read("volume", (image, sampler))
                .read("Points", &input)
                .write("Samples", &output)
                .push(&Push {
                    count: points.len() as u32,
                })
                .dispatch([groups, 1, 1])
        })?;
        let mut values: Vec<[f32; 4]> = output.read(ctx)?;
        values.truncate(points.len());
        Ok(values)
    }
}
