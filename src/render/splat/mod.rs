//! Tiled PSF splatting on the GPU (Csoba & Kunkli 2021, after Franke et al. 2018).
//!
//! Per frame: PSF texture (blend the kernel grid over pupil and focus; then, where neighbouring
//! object distances' radii are close, each distance's own kernel: layer kernels) → fragments (one
//! per pixel) → merge (optional 2×2 / 4×4 blocks) → tile count → prefix sum → band plan → [per band
//! of tile rows: fill → sort → convolve]. List memory is exact (count → prefix sum → fill); when a
//! frame's lists exceed the list buffer (the device's storage-buffer binding limit or the memory
//! budget), the screen is processed in bands of tile rows, planned on the GPU from the prefix sum,
//! so nothing is ever dropped and a banded frame is still one submission.
//!
//! Each pass is one file here plus `glsl/render/splat/<same stem>.comp`, listed once in `passes!`
//! below (`passes` says how to add one); `construct` builds a splatter, `settings` holds its
//! options, `atlas` the PSF texture's layout, `field` the off-axis lattice, `bands` the planning of
//! tile-row bands, `uniform` the frame's uniform block. Values every dispatch of a frame shares are
//! in that block (one persistent buffer, written through its mapping); values that change between
//! dispatches are each pass's own typed push constants.

mod atlas;
mod bands;
#[cfg(test)]
mod block_layouts;
mod construct;
mod field;
mod passes;
mod settings;
mod uniform;

passes::passes! {
    input: input::InputPass,
    psf_texture: psf_texture::PsfTexturePass,
    layer_kernels: layer_kernels::LayerKernelsPass,
    fragments: fragments::FragmentsPass,
    merge: merge::MergePass,
    tile_count: tile_count::TileCountPass,
    prefix_sum: prefix_sum::PrefixSumPass,
    band_plan: band_plan::BandPlanPass,
    tile_fill: tile_fill::TileFillPass,
    tile_sort: tile_sort::TileSortPass,
    convolve: convolve::ConvolvePass,
}

use crate::gpu::{Buffer, Context, GpuError, Image, Residency, Sampler, Timings};
use crate::psf::kernels::KernelGrid;

use bands::{plan_bands, BandPush, BandSlot, PlannedBands};
pub use input::{RecordedInput, RecordedLayer};
pub use psf_texture::PsfTextureFormat;
pub use settings::{
    display_white, ConvolveWalk, MergeSettings, Quality, SplatSettings, DEFAULT_SATURATION_EPSILON,
};
use uniform::FrameBlock;
pub(crate) use uniform::FrameUniform;
pub use uniform::FRAME_UNIFORM_BYTES;

/// Mirrors `struct Fragment` in glsl/common/splat.glsl (std430, 48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Fragment {
    pub color: [f32; 3],
    pub depth: f32,
    pub radius: [f32; 3],
    pub index: f32,
    pub center: [f32; 2],
    pub size: u32,
    /// Vergence along the pixel's ray (D, unclamped): the blend's grouping key.
    pub dioptre: f32,
}

/// A colour + depth frame on the CPU: row-major, top row first.
#[derive(Clone, Copy, Debug)]
pub struct FrameInput<'a> {
    pub width: u32,
    pub height: u32,
    /// Linear RGB (alpha ignored), HDR allowed.
    pub color: &'a [[f32; 4]],
    /// Distance along the view axis in metres; 0, negative or infinite = optical infinity.
    pub depth_m: &'a [f32],
    /// Vertical field of view of the pinhole camera that made the frame (degrees).
    pub fov_y_deg: f64,
    /// The 2nd, 3rd, … surfaces along each pixel's ray (depth peeling, layered EXR), nearest
    /// first; infinite depth where a layer is empty. Empty: the visible surface only.
    pub hidden_layers: &'a [HiddenLayer<'a>],
    /// Where a silhouette splits pixels between surfaces, what lies behind the visible one
    /// (the rasteriser's samples, [`crate::render::Rasterizer::set_mixed_pixels`]); only the
    /// reference reads it, and only with [`crate::render::EdgePixels::Split`]. None: every
    /// pixel is one fragment of colour `color` at depth `depth_m`.
    pub mixed: Option<MixedPixels<'a>>,
}

/// How silhouettes split a frame's pixels (issue 51, docs/validation.md "Mixed pixels"). A
/// pixel a silhouette crosses shows the near surface in part of its area and what lies behind
/// in the rest; one fragment of the mean colour at the near depth blurs the rest with the near
/// surface's kernel and lets the near surface cover the whole pixel. Split, the pixel is two
/// fragments: the near surface's colour with its share of the pixel, and the rest's colour at
/// the rest's depth with the remainder. `color` stays the pixel's mean colour, so a method
/// that does not split reads the frame as before. Measured against the multi-view truth, the
/// split moved the reference's edge band away from it, so no method splits by default.
#[derive(Clone, Copy, Debug)]
pub struct MixedPixels<'a> {
    /// rgb: the mean colour of the samples behind the near surface's depth group; a: that
    /// group's share of the pixel (1 where the pixel shows one surface).
    pub rest: &'a [[f32; 4]],
    /// The nearest distance along the view axis among those samples (m); +∞ where none.
    pub rest_depth_m: &'a [f32],
}

impl MixedPixels<'_> {
    /// The near surface's share of pixel `i` (0 < share ≤ 1).
    pub fn share(&self, i: usize) -> f32 {
        self.rest[i][3].clamp(0.0, 1.0)
    }

    /// The near surface's own colour at pixel `i`, given the pixel's mean `mean`: the mean
    /// with the rest's part taken out.
    pub fn near_color(&self, i: usize, mean: [f32; 4]) -> [f32; 3] {
        let a = self.share(i);
        if a >= 1.0 || a <= 0.0 {
            return [mean[0], mean[1], mean[2]];
        }
        let r = self.rest[i];
        [0, 1, 2].map(|c| ((mean[c] - (1.0 - a) * r[c]) / a).max(0.0))
    }
}

/// One hidden depth layer of a frame: the same layout as the visible one.
#[derive(Clone, Copy, Debug)]
pub struct HiddenLayer<'a> {
    pub color: &'a [[f32; 4]],
    pub depth_m: &'a [f32],
}

impl FrameInput<'_> {
    pub fn projection(&self) -> crate::render::projection::Projection {
        crate::render::projection::Projection {
            width: self.width,
            height: self.height,
            fov_y_deg: self.fov_y_deg,
        }
    }
}

/// The eye's state for one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewState {
    pub pupil_mm: f64,
    pub focus_d: f64,
}

/// What a frame cost in list memory, for reports and tests.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SplatStats {
    pub fragments: u64,
    pub live_fragments: u64,
    pub list_entries: u64,
    /// (pixel, fragment) pairs within reach: the convolution's work, which level of detail
    /// keeps proportional to the pixels whatever the blur.
    pub kernel_evaluations: u64,
    /// Filtered texture reads the pixel walk makes for those pairs, at most: a GPU's cost,
    /// where a pair costs one read (a layer kernel), up to three (the radius levels), four (a
    /// merged block read where its pixels lie in the wide field) or four times that off axis.
    pub texture_reads: u64,
    pub max_entries_per_tile: u64,
    pub bands: u32,
    /// Queue submissions, GPU allocations and host↔device bytes this frame cost (the engine's
    /// counters: a steady-state frame is one submission and no allocation).
    pub submissions: u32,
    pub allocations: u32,
    /// Vulkan objects (command buffers, fences, query and descriptor pools) created for this
    /// frame's submissions: 0 once the device's submission objects are warm.
    pub submission_objects: u64,
    /// Commands recorded and barriers the declared accesses called for (a barrier after every
    /// command would make them equal).
    pub commands: u32,
    pub barriers: u32,
    pub upload_bytes: u64,
    pub readback_bytes: u64,
    /// Device memory of the PSF texture.
    pub psf_texture_bytes: u64,
    /// Whether the convolution read each object distance's own kernel (the layer texture,
    /// one read per pixel and fragment) rather than the radius levels.
    pub layer_kernels: bool,
}

/// The layer kernels in single floats (`Splatter::layer_sums`; glsl/common/layer_atlas.glsl):
/// one layer per object distance, region 0 (on axis).
pub struct LayerSums<'a> {
    pub image: &'a Image,
    pub sampler: &'a Sampler,
    /// The texel of the plain kernel's offset 0.
    pub plain_texel: [u32; 2],
    /// The texel of the summed-area table's first corner, (−R − ½, −R − ½).
    pub table_texel: [u32; 2],
    /// R: the slots hold kernels up to this radius.
    pub max_radius_px: u32,
}

/// Intermediate buffers of a single-band frame, read back for tests.
#[derive(Clone, Debug, Default)]
pub struct SplatIntermediates {
    pub fragments: Vec<Fragment>,
    pub counts: Vec<u32>,
    pub offsets: Vec<u32>,
    pub entries: Vec<[u32; 2]>,
}

pub struct SplatOutput {
    pub color: Vec<[f32; 4]>,
    pub timings: Timings,
    pub stats: SplatStats,
    pub intermediates: Option<SplatIntermediates>,
}

/// Frame-size-dependent GPU resources, rebuilt when the size changes.
struct FrameResources {
    width: u32,
    height: u32,
    layers: u32,
    tiles_x: u32,
    tiles_y: u32,
    color_in: Image,
    depth_in: Image,
    color_out: Image,
    fragments: fragments::FragmentStore,
    counts: Buffer,
    cursors: Buffer,
    offsets: Buffer,
    block_sums: Buffer,
    /// The bands the GPU planned (glsl/render/splat/band_plan.comp) and their dispatches.
    band_table: Buffer,
    /// The frame's `FrameUniform`, written through its mapping before each submission.
    uniform: Buffer,
    /// Persistent, mapped transfer buffers: host inputs in (made at the first host frame),
    /// the image and the list sizes out.
    staging: Option<input::Staging>,
    readback_color: Buffer,
    /// counts (tiles + 1, the last = live fragments), offsets (tiles + 1, the last = total),
    /// then the band table's header ([`band_header_at`]).
    readback_lists: Buffer,
}

/// What the passes of a frame bind: the frame's uniform block and per-size resources, and the
/// splatter's tables and PSF texture. Each pass's `record` takes it whole and binds what its
/// shader names.
#[derive(Clone, Copy)]
struct Resources<'a> {
    block: FrameBlock<'a>,
    frame: &'a FrameResources,
    radii: &'a Buffer,
    field_table: &'a Buffer,
    texture: &'a Image,
    sampler: &'a Sampler,
    atlas: &'a Buffer,
    layer_texture: &'a Image,
    /// The layer kernels and their summed-area tables in single floats (the layer texture
    /// itself where that is single floats).
    layer_sums: &'a Image,
    layer_atlas: &'a Buffer,
}

pub struct Splatter {
    ctx: Context,
    settings: SplatSettings,
    /// On axis the grid; off axis the node nearest the axis (axes and radius are shared).
    grid: KernelGrid,
    /// Off axis: every field node's grid (h-major) and the lattice; on axis empty and None.
    node_grids: Vec<KernelGrid>,
    field_axes: Option<crate::psf::field::FieldAxes>,
    /// Per node (on axis one), every kernel set resident on the GPU.
    resident: Vec<psf_texture::ResidentGrid>,
    layout: atlas::TextureLayout,
    /// The texture's layout for the shaders (glsl/common/atlas.glsl), written once.
    atlas: Buffer,
    /// Each object distance's own kernel (`layer_kernels`): its layout, the layout for the
    /// shaders (glsl/common/layer_atlas.glsl), the texture, and whether frames may use it (on
    /// axis, `SplatSettings::layer_kernels`, within the device's limits; otherwise a 1-texel
    /// stand-in the convolution binds but never reads).
    layer_layout: atlas::LayerLayout,
    layer_atlas: Buffer,
    layer_texture: Image,
    /// Where the layer texture holds halves: the same slots in single floats, with the
    /// summed-area tables that merged blocks read in the wide field
    /// (glsl/common/layer_atlas.glsl); None where the layer texture is single floats.
    layer_sums: Option<Image>,
    layer_kernels: bool,
    field_table: field::FieldTable,
    texture: Image,
    sampler: Sampler,
    radii: Buffer,
    radii_staging: Buffer,
    /// The blend the PSF texture holds (None: not built yet).
    texture_blend: Option<crate::psf::kernels::GridBlend>,
    /// Lists of the last frame: total entries and bands (decides the one-submission path and
    /// its band slots).
    last_lists: Option<(u64, u32)>,
    /// Per set, the core radius of every object's kernels (see `KernelSet::core_radii_px`).
    core_radii: Vec<Vec<[f32; 3]>>,
    /// Per set, the peak radius of every object's kernels (see `KernelSet::peak_radii_px`).
    peak_radii: Vec<Vec<[f32; 3]>>,
    frame: Option<FrameResources>,
    entries: Option<Buffer>,
    passes: Passes,
}

/// Largest tile side of the off-axis convolution.
pub const MAX_OFF_AXIS_TILE: u32 = 16;

pub(super) const FRAGMENT_BYTES: u64 = std::mem::size_of::<Fragment>() as u64;
const ENTRY_BYTES: u64 = 8;

/// Where the band table's header lies in the list-sizes read-back of a frame of `tiles` tiles.
pub(super) fn band_header_at(tiles: u64) -> u64 {
    2 * (tiles + 1) * 4
}

/// Band slots a steady frame records after a frame of `bands` bands: as many, and one spare
/// when the frame is banded (lists that grow a little may need one more).
fn steady_slots(bands: u32) -> u32 {
    bands + u32::from(bands > 1)
}

pub(super) fn binding_limit(ctx: &Context) -> u64 {
    u64::from(ctx.limits().max_storage_buffer_range)
}

/// Most depth layers whose fragments fit one storage-buffer binding at `width`×`height`.
pub fn max_layers(ctx: &Context, width: u32, height: u32) -> u32 {
    let per_layer = u64::from(width) * u64::from(height) * FRAGMENT_BYTES;
    (binding_limit(ctx) / per_layer.max(1)).min(u64::from(u32::MAX)) as u32
}

impl Splatter {
    pub fn grid(&self) -> &KernelGrid {
        &self.grid
    }

    pub fn settings(&self) -> &SplatSettings {
        &self.settings
    }

    /// The value the image will be shown as white (`MergeSettings::white`), from the next
    /// frame on.
    pub fn set_display_white(&mut self, white: f32) {
        self.settings.merge.white = white;
    }

    /// The PSF texture as the convolution pass samples it (for inspection and tests).
    pub fn psf_texture(&self) -> (&Image, &Sampler) {
        (&self.texture, &self.sampler)
    }

    /// Device memory of the PSF texture and the layer texture (bytes).
    pub fn psf_texture_bytes(&self) -> u64 {
        let texel = self.settings.texture_format.texel_bytes();
        let sums = self
            .layer_sums
            .as_ref()
            .map_or(0, |_| self.layer_layout.bytes(16));
        self.layout.bytes(texel) + self.layer_layout.bytes(texel) + sums
    }

    /// Whether a frame with these per-object radii (xyz, px) reads the layer texture, and the
    /// largest radius step between neighbouring object distances it must then reach past a
    /// fragment's own radius: where every step is at most `LAYER_RADIUS_STEP_MAX_PX` and no
    /// coarser than the radius levels the layer kernels replace (neighbours within one level:
    /// ¼ px below 2 px). Near focus a kernel's shape changes fastest, and there a coarser step
    /// measurably lost to the levels (validation.md, "Layer kernels").
    fn layer_radius_step(&self, radii: &[[f32; 4]]) -> Option<f32> {
        if !self.layer_kernels {
            return None;
        }
        let most = self.grid.max_radius_px as f32;
        let mut step = 0.0f32;
        for w in radii.windows(2) {
            for (&a, &b) in w[0][..3].iter().zip(&w[1][..3]) {
                let (a, b) = (a.min(most), b.min(most));
                let levels = crate::psf::kernels::level_of_radius(f64::from(a))
                    - crate::psf::kernels::level_of_radius(f64::from(b));
                if levels.abs() > 1.0 {
                    return None;
                }
                step = step.max((b - a).abs());
            }
        }
        (step <= settings::LAYER_RADIUS_STEP_MAX_PX).then_some(step)
    }

    /// The texel at the centre of radius level `level`'s kernel of field node `node` (on axis
    /// 0) in the PSF texture; its layer is the object distance's index.
    pub fn psf_texture_centre(&self, node: u32, level: u32) -> [u32; 2] {
        self.layout.centre(node, level)
    }

    /// Where radius level `level`'s kernel summed over merged blocks of `side` × `side` pixels
    /// (4 … 32) lies at field node `node`, if the texture holds it: the texel whose centre is
    /// offset (+½, +½) from the block's centre (glsl/common/atlas.glsl).
    /// The layer kernels in single floats as the convolution samples them (for inspection and
    /// tests); None where this splatter has no layer kernels.
    pub fn layer_sums(&self) -> Option<LayerSums<'_>> {
        if !self.layer_kernels {
            return None;
        }
        let kinds = &self.layer_layout.kinds;
        Some(LayerSums {
            image: self.layer_sums.as_ref().unwrap_or(&self.layer_texture),
            sampler: &self.sampler,
            plain_texel: kinds[0]?.0,
            table_texel: kinds[atlas::SAT_KIND]?.0,
            max_radius_px: self.layer_layout.max_radius,
        })
    }

    pub fn psf_texture_block_centre(&self, node: u32, level: u32, side: u32) -> Option<[u32; 2]> {
        let (b, slot) = self.layout.blocks.iter().find(|(b, _)| b.side == side)?;
        (level >= b.first_level).then(|| {
            self.layout
                .slot_centre(node, (slot + level - b.first_level) as usize)
        })
    }

    /// Renders one frame through the eye's kernels for `view`.
    pub fn render(
        &mut self,
        input: &FrameInput<'_>,
        view: ViewState,
        keep_intermediates: bool,
    ) -> crate::Result<SplatOutput> {
        self.render_from(input::Source::Host(input), view, keep_intermediates)
    }

    /// Renders a frame the GPU makes within splat's own submission (a rasterised scene): in
    /// steady state the whole frame is one submission, and only the output image and two list
    /// sizes cross to the host.
    pub fn render_recorded(
        &mut self,
        frame: &mut dyn RecordedInput,
        view: ViewState,
    ) -> crate::Result<SplatOutput> {
        self.render_from(input::Source::Gpu(frame), view, false)
    }

    fn render_from(
        &mut self,
        mut source: input::Source<'_, '_>,
        view: ViewState,
        keep_intermediates: bool,
    ) -> crate::Result<SplatOutput> {
        let shape = source.shape()?;
        let (w, h) = (shape.width, shape.height);
        let pixels = w as usize * h as usize;
        if !(view.pupil_mm.is_finite() && view.pupil_mm > 0.0 && view.focus_d.is_finite()) {
            return Err(crate::Error::input(format!(
                "pupil {} mm / focus {} D must be finite, pupil positive",
                view.pupil_mm, view.focus_d
            )));
        }
        let ctx = self.ctx.clone();
        let allocations_before = ctx.allocations();
        let objects_before = ctx.submission_objects_created();
        self.ensure_frame(w, h, shape.layers)?;
        let blend = self.grid.blend(view.pupil_mm, view.focus_d);
        // xyz: natural radius per channel; w: the smallest core radius over the channels,
        // which decides merging.
        let core = self.grid.blend_per_object(&blend, &self.core_radii);
        let radii: Vec<[f32; 4]> = self
            .grid
            .blended_radii(&blend)
            .iter()
            .zip(&core)
            .map(|(r, k)| [r[0], r[1], r[2], k[0].min(k[1]).min(k[2])])
            .collect();
        // Inputs and radii go through persistent mapped buffers: no allocation per frame.
        let input_bytes = source.stage(&ctx, self.frame.as_mut().expect("ensured above"))?;
        // After them, per object distance, the smallest peak radius over the channels (x),
        // which bounds what averaging a block's colours can move, and the radius of the
        // highest level the kernels hold there (y), which bounds a merged block's radius
        // (merge.comp; off axis every node holds every level).
        let peak = self.grid.blend_per_object(&blend, &self.peak_radii);
        let tops = if self.node_grids.is_empty() {
            self.grid.blended_top_radius_px(&blend)
        } else {
            vec![f32::MAX; peak.len()]
        };
        let peaks: Vec<[f32; 4]> = peak
            .iter()
            .zip(&tops)
            .map(|(p, &top)| [p[0].min(p[1]).min(p[2]), top, 0.0, 0.0])
            .collect();
        self.radii_staging.write_mapped(0, &radii)?;
        self.radii_staging.write_mapped(radii.len(), &peaks)?;
        let table = self.field_table.contents(self.nodes(), &blend);
        self.field_table.staging.write_mapped(0, &table)?;
        let projection = crate::render::projection::Projection {
            width: w,
            height: h,
            fov_y_deg: shape.fov_y_deg,
        };
        let mut params = self.params(
            self.frame.as_ref().expect("ensured above"),
            projection.focal_px() as f32,
        );
        let step = self.layer_radius_step(&radii);
        params.radius_step = step.unwrap_or(0.0);
        params.layered = u32::from(step.is_some());
        // Through the persistent mapping: submissions complete before `submit` returns, so no
        // earlier frame still reads it.
        let frame_mut = self.frame.as_mut().expect("ensured above");
        frame_mut
            .uniform
            .write_mapped(0, std::slice::from_ref(&params))?;
        let upload_bytes =
            input_bytes + radii.len() as u64 * 32 + table.len() as u64 * 16 + FRAME_UNIFORM_BYTES;
        let frame = self.frame.as_ref().expect("ensured above");
        let hidden = self.hidden_light(&params, &radii, view);
        let block = FrameBlock {
            values: &params,
            buffer: &frame.uniform,
        };
        let r = self.resources(frame, block);
        let tiles = frame.tiles_x * frame.tiles_y;
        let rebuild_texture = self.texture_blend.as_ref() != Some(&blend);
        let output_bytes = pixels as u64 * 16;

        // Steady state: the whole frame in one submission, with the list buffer of earlier
        // frames and as many band slots as the last frame needed (one spare when banded); the
        // bands are planned on the GPU and only the band table's header comes back. A frame
        // whose lists outgrew the buffer or the slots is rendered again below, planned on the
        // host.
        let one_submission = !keep_intermediates
            && self.settings.steady_state
            && self.entries.is_some()
            && self.last_lists.is_some();
        let header_at = band_header_at(u64::from(tiles));
        let mut submissions = 0u32;
        let mut sync = (0u32, 0u32);
        if one_submission {
            let entries = self.entries.as_ref().expect("checked above");
            let slots = steady_slots(self.last_lists.map_or(1, |(_, bands)| bands));
            let timings = ctx.submit(|rec| {
                let texture = rebuild_texture.then_some(&blend);
                self.record_front(rec, &source, &r, texture, hidden)?;
                self.record_back(rec, &r, slots, entries)?;
                sync = rec.barrier_counts();
                Ok(())
            })?;
            submissions += 1;
            let planned = read_band_header(&frame.readback_lists, header_at)?;
            if planned.complete() {
                self.texture_blend = Some(blend);
                self.last_lists = Some((u64::from(planned.total_entries), planned.bands));
                let stats = SplatStats {
                    fragments: pixels as u64,
                    live_fragments: u64::from(planned.live_fragments),
                    list_entries: u64::from(planned.total_entries),
                    kernel_evaluations: planned.kernel_evaluations,
                    texture_reads: planned.texture_reads,
                    max_entries_per_tile: 0,
                    bands: planned.bands,
                    submissions,
                    allocations: (ctx.allocations() - allocations_before) as u32,
                    submission_objects: ctx.submission_objects_created() - objects_before,
                    barriers: sync.0,
                    commands: sync.1,
                    upload_bytes,
                    readback_bytes: output_bytes + bands::BAND_TABLE_HEADER_BYTES,
                    psf_texture_bytes: self.psf_texture_bytes(),
                    layer_kernels: params.layered != 0,
                };
                let color: Vec<[f32; 4]> = frame.readback_color.read_mapped_all()?;
                check_every_pixel_written(&color, w as usize)?;
                return Ok(SplatOutput {
                    color,
                    timings: merge_repeated(timings),
                    stats,
                    intermediates: None,
                });
            }
        }

        // Planning frame: everything up to the exact list sizes, read back to size the list
        // buffer and count the bands; the GPU then plans the same bands (checked below).
        let mut timings = ctx.submit(|rec| {
            self.record_front(rec, &source, &r, Some(&blend), hidden)?;
            rec.end_pass();
            rec.copy_buffer_region(
                &frame.counts,
                0,
                &frame.readback_lists,
                0,
                u64::from(tiles + 1) * 4,
            );
            rec.copy_buffer_region(
                &frame.offsets,
                0,
                &frame.readback_lists,
                u64::from(tiles + 1) * 4,
                u64::from(tiles + 1) * 4,
            );
            let (b, c) = rec.barrier_counts();
            sync = (sync.0 + b, sync.1 + c);
            Ok(())
        })?;
        submissions += 1;
        let sizes: Vec<u32> = frame.readback_lists.read_mapped_all()?;
        let counts = sizes[..tiles as usize].to_vec();
        let live = u64::from(sizes[tiles as usize]);
        let offsets = sizes[tiles as usize + 1..2 * (tiles as usize + 1)].to_vec();
        let total: u64 = counts.iter().map(|&c| u64::from(c)).sum();
        if total != u64::from(offsets[tiles as usize]) {
            return Err(GpuError::Usage {
                pass: "prefix sum".into(),
                message: format!(
                    "list total {} disagrees with the counts' sum {total} (more than 2³² entries?)",
                    offsets[tiles as usize]
                ),
            }
            .into());
        }
        let largest_band = plan_bands(&counts, frame.tiles_x, self.list_capacity_entries())?
            .iter()
            .map(|b| b.entries)
            .max()
            .unwrap_or(0);
        self.ensure_entries(largest_band)?;
        let frame = self.frame.as_ref().expect("ensured above");
        let block = FrameBlock {
            values: &params,
            buffer: &frame.uniform,
        };
        let r = self.resources(frame, block);
        let entries = self.entries.as_ref().expect("ensured above");
        // The bands of the buffer actually made (it may hold more than the largest band, never
        // less): the plan every later steady frame repeats on the GPU.
        let bands = plan_bands(&counts, frame.tiles_x, u64::from(entries_in(entries)))?;
        let slots = bands.len() as u32;
        let band_timings = ctx.submit(|rec| {
            self.record_back(rec, &r, slots, entries)?;
            let (b, c) = rec.barrier_counts();
            sync = (sync.0 + b, sync.1 + c);
            Ok(())
        })?;
        submissions += 1;
        let planned = read_band_header(&frame.readback_lists, header_at)?;
        if !planned.complete() || planned.bands != slots {
            return Err(GpuError::Usage {
                pass: "band plan".into(),
                message: format!(
                    "the GPU planned {} band(s) (status {}), the host {slots}",
                    planned.bands, planned.status
                ),
            }
            .into());
        }
        timings.extend(band_timings);
        self.texture_blend = Some(blend);
        self.last_lists = Some((total, slots));
        let color: Vec<[f32; 4]> = frame.readback_color.read_mapped_all()?;
        check_every_pixel_written(&color, w as usize)?;
        let stats = SplatStats {
            fragments: pixels as u64,
            live_fragments: live,
            list_entries: total,
            kernel_evaluations: planned.kernel_evaluations,
            texture_reads: planned.texture_reads,
            max_entries_per_tile: counts.iter().copied().max().unwrap_or(0).into(),
            bands: slots,
            submissions,
            allocations: (ctx.allocations() - allocations_before) as u32,
            submission_objects: ctx.submission_objects_created() - objects_before,
            barriers: sync.0,
            commands: sync.1,
            upload_bytes,
            readback_bytes: output_bytes + header_at + bands::BAND_TABLE_HEADER_BYTES,
            psf_texture_bytes: self.psf_texture_bytes(),
            layer_kernels: params.layered != 0,
        };
        let intermediates = if keep_intermediates {
            let mut all_entries: Vec<[u32; 2]> = entries.read(&ctx)?;
            all_entries.truncate(if slots == 1 { total as usize } else { 0 });
            let fragments: Vec<Fragment> = frame.fragments.buffer.read(&ctx)?;
            Some(SplatIntermediates {
                fragments,
                counts,
                offsets,
                entries: all_entries,
            })
        } else {
            None
        };
        Ok(SplatOutput {
            color,
            timings: merge_repeated(timings),
            stats,
            intermediates,
        })
    }

    /// What the fragments pass needs to judge hidden-layer light: the eye's focus (the object
    /// vergence whose green kernel is smallest) and the parallax of the pupil's edge.
    fn hidden_light(
        &self,
        params: &FrameUniform,
        radii: &[[f32; 4]],
        view: ViewState,
    ) -> fragments::HiddenLight {
        let sharpest = radii
            .iter()
            .enumerate()
            .min_by(|a, b| a.1[1].total_cmp(&b.1[1]))
            .map_or(0, |(i, _)| i);
        fragments::HiddenLight {
            pupil_visibility: self.settings.pupil_visibility,
            focus_d: params.dioptre_min + params.dioptre_step * sharpest as f32,
            parallax_px_per_d: (view.pupil_mm * 0.5e-3) as f32 * params.focal_px,
        }
    }

    /// What the passes of `frame` bind.
    fn resources<'a>(&'a self, frame: &'a FrameResources, block: FrameBlock<'a>) -> Resources<'a> {
        Resources {
            block,
            frame,
            radii: &self.radii,
            field_table: &self.field_table.buffer,
            texture: &self.texture,
            sampler: &self.sampler,
            atlas: &self.atlas,
            layer_texture: &self.layer_texture,
            layer_sums: self.layer_sums.as_ref().unwrap_or(&self.layer_texture),
            layer_atlas: &self.layer_atlas,
        }
    }

    /// Records the passes before the lists: inputs, PSF texture (given the blend when it
    /// changed), fragments, merging, tile counts and their prefix sum.
    fn record_front(
        &self,
        rec: &mut crate::gpu::Recorder<'_>,
        source: &input::Source<'_, '_>,
        r: &Resources<'_>,
        rebuild_texture: Option<&crate::psf::kernels::GridBlend>,
        hidden: fragments::HiddenLight,
    ) -> crate::gpu::GpuResult<()> {
        let frame = r.frame;
        source.record(rec, &self.passes.input, frame)?;
        rec.copy_buffer(&self.radii_staging, &self.radii, self.radii.size_bytes());
        rec.copy_buffer(
            &self.field_table.staging,
            &self.field_table.buffer,
            self.field_table.buffer.size_bytes(),
        );
        if let Some(blend) = rebuild_texture {
            rec.begin_pass("psf texture");
            if self.texture_blend.is_none() {
                // A read near a ring's outer edge may touch the next texel with weight zero (the
                // filter's subtexel rounding), and unwritten memory may hold NaN, which a zero
                // weight keeps: the atlas's gaps are zeroed once, before its first blocks.
                // (Measured: without it, two splat tests read NaN on lavapipe.)
                rec.clear_image(&self.texture, [0.0; 4]);
            }
            let blocks: Vec<atlas::BlockKernels> = self.layout.blocks.iter().map(|b| b.0).collect();
            self.passes
                .psf_texture
                .record(rec, r, &self.resident, blend, &blocks)?;
            if r.block.values.layered != 0 {
                rec.begin_pass("layer kernels");
                // The slots' rings and the gaps between regions must read zero (see above).
                rec.clear_image(&self.layer_texture, [0.0; 4]);
                if let Some(sums) = &self.layer_sums {
                    rec.clear_image(sums, [0.0; 4]);
                }
                self.passes
                    .layer_kernels
                    .record(rec, r, &self.layer_layout)?;
            }
        }
        rec.begin_pass("fragments");
        self.passes.fragments.record(rec, r, hidden)?;
        let merge = &self.settings.merge;
        if merge.levels > 0 {
            rec.begin_pass("merge");
            self.passes.merge.record(rec, r, merge)?;
        }
        rec.begin_pass("tile count");
        // Alpha 0 marks a pixel the convolution has not written (it writes alpha 1 to every
        // pixel of its tiles): the host checks the frame it reads back.
        rec.clear_image(&frame.color_out, [0.0; 4]);
        rec.fill_buffer(&frame.counts, 0);
        self.passes.tile_count.record(rec, r)?;
        rec.begin_pass("prefix sum");
        self.passes.prefix_sum.record(rec, r)?;
        Ok(())
    }

    /// Records the passes after the prefix sum: the band plan, `slots` bands' list fill, sort
    /// and convolution, and the read-back of the band table's header and the image.
    fn record_back(
        &self,
        rec: &mut crate::gpu::Recorder<'_>,
        r: &Resources<'_>,
        slots: u32,
        entries: &Buffer,
    ) -> crate::gpu::GpuResult<()> {
        let frame = r.frame;
        let entry_capacity = entries_in(entries);
        rec.begin_pass("band plan");
        self.passes
            .band_plan
            .record(rec, r, (slots, entry_capacity))?;
        for slot in 0..slots {
            let band = BandSlot {
                push: BandPush {
                    slot,
                    entry_capacity,
                },
                entries,
            };
            rec.begin_pass("tile fill");
            rec.fill_buffer(&frame.cursors, 0);
            self.passes.tile_fill.record(rec, r, &band)?;
            rec.begin_pass("tile sort");
            self.passes.tile_sort.record(rec, r, &band)?;
            rec.begin_pass("convolve");
            self.passes.convolve.record(rec, r, &band)?;
        }
        rec.copy_buffer_region(
            &frame.band_table,
            0,
            &frame.readback_lists,
            band_header_at(u64::from(frame.tiles_x * frame.tiles_y)),
            bands::BAND_TABLE_HEADER_BYTES,
        );
        rec.end_pass();
        rec.copy_image_to_buffer(&frame.color_out, &frame.readback_color);
        Ok(())
    }

    /// Entries one band may hold: the binding limit, the memory budget, and a test override.
    fn list_capacity_entries(&self) -> u64 {
        binding_limit(&self.ctx).min(self.settings.max_list_bytes) / ENTRY_BYTES
    }

    fn ensure_entries(&mut self, entries: u64) -> crate::Result<()> {
        let needed = entries.max(1) * ENTRY_BYTES;
        if self
            .entries
            .as_ref()
            .is_some_and(|b| b.size_bytes() >= needed)
        {
            return Ok(());
        }
        // Grow with headroom so that small frame-to-frame changes do not reallocate.
        let size = (needed + needed / 4)
            .min(self.list_capacity_entries() * ENTRY_BYTES)
            .max(needed);
        self.entries = None;
        self.entries = Some(Buffer::new(
            &self.ctx,
            "tile lists",
            size,
            Residency::Device,
        )?);
        Ok(())
    }
}

/// The band table's header from the list-sizes read-back.
fn read_band_header(readback: &Buffer, at: u64) -> crate::gpu::GpuResult<PlannedBands> {
    let words = readback
        .read_mapped::<u32>(at as usize / 4, bands::BAND_TABLE_HEADER_BYTES as usize / 4)?;
    Ok(PlannedBands::from_header(&words))
}

/// Entries a list buffer holds.
fn entries_in(entries: &Buffer) -> u32 {
    (entries.size_bytes() / ENTRY_BYTES).min(u64::from(u32::MAX)) as u32
}

/// Refuses a frame in which the convolution left pixels unwritten (alpha still 0 from the
/// clear). Lavapipe (Mesa 22.3) was seen to drop whole rows of some workgroups' pixels on tiles
/// with very long lists (off axis at 960×540 and up): a partial frame must not reach an output.
fn check_every_pixel_written(color: &[[f32; 4]], width: usize) -> crate::gpu::GpuResult<()> {
    let mut unwritten = color.iter().enumerate().filter(|(_, p)| p[3] != 1.0);
    let Some((first, _)) = unwritten.next() else {
        return Ok(());
    };
    Err(GpuError::DroppedWork {
        pass: "convolve".into(),
        unwritten: 1 + unwritten.count(),
        total: color.len(),
        x: first % width.max(1),
        y: first / width.max(1),
    })
}

/// Sums the timings of passes that ran once per band, keeping first-seen order.
fn merge_repeated(timings: Timings) -> Timings {
    let mut out = Timings::default();
    for pass in timings.passes {
        match out.passes.iter_mut().find(|p| p.name == pass.name) {
            Some(existing) => existing.ms += pass.ms,
            None => out.passes.push(pass),
        }
    }
    out
}

#[cfg(test)]
mod written_check_tests {
    use super::*;

    #[test]
    fn a_frame_with_an_unwritten_pixel_is_refused_and_the_first_one_named() {
        let mut color = vec![[0.5, 0.5, 0.5, 1.0]; 12];
        assert!(check_every_pixel_written(&color, 4).is_ok());
        // Alpha 0 is what the clear leaves; a written pixel of zero light still has alpha 1.
        color[0] = [0.0, 0.0, 0.0, 1.0];
        assert!(check_every_pixel_written(&color, 4).is_ok());
        color[6] = [0.5, 0.5, 0.5, 0.0];
        color[9] = [0.0; 4];
        match check_every_pixel_written(&color, 4) {
            Err(GpuError::DroppedWork {
                unwritten,
                total,
                x,
                y,
                ..
            }) => assert_eq!((unwritten, total, x, y), (2, 12, 2, 1)),
            other => panic!("expected DroppedWork, got {other:?}"),
        }
    }
}
