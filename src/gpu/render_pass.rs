//! Recording graphics work: render passes and draws, for pipelines from `graphics.rs`. Draws
//! bind resources exactly as dispatches do; the render pass's own dependencies order it
//! against the work before and after.

use ash::vk;

use super::buffer::Buffer;
use super::commands::Recorder;
use super::error::{GpuError, GpuResult};
use super::graphics::{Framebuffer, GraphicsPipeline};
use super::pipeline::Binding;

impl Recorder<'_> {
    /// Begins `pipeline`'s render pass on `framebuffer`, clearing colour target i to
    /// `clear_colors[i]` and depth to `clear_depth`, sets the viewport to the whole framebuffer
    /// and binds the pipeline. Draws follow; `end_render_pass` closes it.
    pub fn begin_render_pass(
        &mut self,
        pipeline: &GraphicsPipeline,
        framebuffer: &Framebuffer,
        clear_colors: &[[f32; 4]],
        clear_depth: f32,
    ) -> GpuResult<()> {
        let parts = pipeline.render_pass_parts();
        let usage = |message: String| GpuError::Usage {
            pass: pipeline.name().to_string(),
            message,
        };
        if let Some(open) = &self.render_pass_open {
            return Err(usage(format!("render pass of \"{open}\" is still open")));
        }
        // A render pass is a full synchronisation point: its attachments and bindings are not
        // tracked one by one.
        if self.hazards.pending() {
            self.barrier();
        }
        if clear_colors.len() != parts.color_count {
            return Err(usage(format!(
                "{} clear colours given, the pipeline has {} colour targets",
                clear_colors.len(),
                parts.color_count
            )));
        }
        let expected = parts.color_count + parts.resolve_count + usize::from(parts.has_depth);
        if framebuffer.attachment_count() != expected {
            return Err(usage("framebuffer was made for another pipeline".into()));
        }
        let mut clears: Vec<vk::ClearValue> = clear_colors
            .iter()
            .map(|&c| vk::ClearValue {
                color: vk::ClearColorValue { float32: c },
            })
            .collect();
        // Resolve targets are not cleared; their entries are placeholders.
        clears.extend((0..parts.resolve_count).map(|_| vk::ClearValue::default()));
        if parts.has_depth {
            clears.push(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: clear_depth,
                    stencil: 0,
                },
            });
        }
        let area = vk::Rect2D {
            offset: vk::Offset2D { x: 0, y: 0 },
            extent: vk::Extent2D {
                width: framebuffer.width(),
                height: framebuffer.height(),
            },
        };
        let info = vk::RenderPassBeginInfo::default()
            .render_pass(parts.render_pass)
            .framebuffer(framebuffer.raw())
            .render_area(area)
            .clear_values(&clears);
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: framebuffer.width() as f32,
            height: framebuffer.height() as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        let device = self.device().clone();
        // SAFETY: recording outside any render pass; the framebuffer matches the render pass
        // (checked when it was made) and outlives the submission (callers hold it).
        unsafe {
            device.cmd_begin_render_pass(self.cmd, &info, vk::SubpassContents::INLINE);
            device.cmd_bind_pipeline(
                self.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                pipeline.parts().pipeline,
            );
            device.cmd_set_viewport(self.cmd, 0, &[viewport]);
            device.cmd_set_scissor(self.cmd, 0, &[area]);
        }
        self.render_pass_open = Some(pipeline.name().to_string());
        Ok(())
    }

    /// Draws `index_count` indexed triangles (u32 indices from `first_index`) from one
    /// interleaved vertex buffer, with `bindings` and `push_constants` as for `dispatch`.
    #[allow(clippy::too_many_arguments)]
    pub fn draw_indexed<P: bytemuck::Pod>(
        &mut self,
        pipeline: &GraphicsPipeline,
        bindings: &[Binding<'_>],
        push_constants: &P,
        vertices: &Buffer,
        indices: &Buffer,
        first_index: u32,
        index_count: u32,
    ) -> GpuResult<()> {
        self.check_in_render_pass(pipeline)?;
        if (u64::from(first_index) + u64::from(index_count)) * 4 > indices.size_bytes() {
            return Err(GpuError::Usage {
                pass: pipeline.name().to_string(),
                message: format!(
                    "indices {first_index}..{} lie past the end of index buffer \"{}\"",
                    first_index + index_count,
                    indices.name()
                ),
            });
        }
        self.bind(
            &pipeline.parts(),
            bindings,
            bytemuck::bytes_of(push_constants),
        )?;
        if index_count == 0 {
            return Ok(());
        }
        // SAFETY: recording inside the pipeline's render pass; buffers have vertex and index
        // usage and outlive the submission.
        unsafe {
            let device = self.device();
            device.cmd_bind_vertex_buffers(self.cmd, 0, &[vertices.raw()], &[0]);
            device.cmd_bind_index_buffer(self.cmd, indices.raw(), 0, vk::IndexType::UINT32);
            device.cmd_draw_indexed(self.cmd, index_count, 1, first_index, 0, 0);
        }
        Ok(())
    }

    /// Draws `vertex_count` vertices as triangles; `vertices` may be `None` for shaders that
    /// make their own (a full-screen triangle from `gl_VertexIndex`).
    pub fn draw<P: bytemuck::Pod>(
        &mut self,
        pipeline: &GraphicsPipeline,
        bindings: &[Binding<'_>],
        push_constants: &P,
        vertices: Option<&Buffer>,
        vertex_count: u32,
    ) -> GpuResult<()> {
        self.check_in_render_pass(pipeline)?;
        self.bind(
            &pipeline.parts(),
            bindings,
            bytemuck::bytes_of(push_constants),
        )?;
        if vertex_count == 0 {
            return Ok(());
        }
        // SAFETY: recording inside the pipeline's render pass.
        unsafe {
            let device = self.device();
            if let Some(v) = vertices {
                device.cmd_bind_vertex_buffers(self.cmd, 0, &[v.raw()], &[0]);
            }
            device.cmd_draw(self.cmd, vertex_count, 1, 0, 0);
        }
        Ok(())
    }

    /// Ends the open render pass; a barrier follows, so later passes see its results.
    pub fn end_render_pass(&mut self) -> GpuResult<()> {
        if self.render_pass_open.take().is_none() {
            return Err(GpuError::Usage {
                pass: "end_render_pass".into(),
                message: "no render pass is open".into(),
            });
        }
        // SAFETY: a render pass begun by begin_render_pass is open on this command buffer.
        unsafe { self.device().cmd_end_render_pass(self.cmd) };
        self.barrier();
        Ok(())
    }

    fn check_in_render_pass(&self, pipeline: &GraphicsPipeline) -> GpuResult<()> {
        match &self.render_pass_open {
            Some(name) if name == pipeline.name() => Ok(()),
            Some(name) => Err(GpuError::Usage {
                pass: pipeline.name().to_string(),
                message: format!("draw inside the render pass of \"{name}\""),
            }),
            None => Err(GpuError::Usage {
                pass: pipeline.name().to_string(),
                message: "draw outside a render pass (call begin_render_pass first)".into(),
            }),
        }
    }
}
