//! Building a splatter: the kernels resident on the GPU (on axis one grid, off axis one per
//! field node), the PSF texture's layout, every pass, and the per-frame resources.

use super::bands::{band_table_bytes, BAND_TABLE_HEADER_BYTES};
use super::{
    atlas, band_header_at, binding_limit, field, fragments, passes, psf_texture, FrameResources,
    Passes, SplatSettings, Splatter, FRAGMENT_BYTES, FRAME_UNIFORM_BYTES, MAX_OFF_AXIS_TILE,
};
use crate::gpu::{
    Buffer, Context, Edge, GpuError, Image, ImageUsage, Residency, Sampler, TexelFormat,
};
use crate::psf::kernels::{KernelGrid, KernelSet};

impl Splatter {
    /// Uploads `grid` and builds every pass. The grid stays resident on the GPU.
    pub fn new(
        ctx: &Context,
        grid: KernelGrid,
        settings: SplatSettings,
    ) -> crate::Result<Splatter> {
        grid.validate()
            .map_err(|e| crate::Error::Input(format!("kernel grid: {e}")))?;
        Self::build(ctx, grid, Vec::new(), None, settings)
    }

    /// Off axis: every node's grid resident, one PSF-texture tile per node, and each
    /// fragment's kernel mixed from the four nodes around its direction.
    pub fn new_field(
        ctx: &Context,
        field: crate::psf::field_kernels::KernelField,
        settings: SplatSettings,
    ) -> crate::Result<Splatter> {
        field
            .validate()
            .map_err(|e| crate::Error::Input(format!("field kernels: {e}")))?;
        let nearest = field.nearest_to_axis();
        let grid = field.grids[nearest].clone();
        Self::build(ctx, grid, field.grids, Some(field.axes), settings)
    }

    fn build(
        ctx: &Context,
        grid: KernelGrid,
        node_grids: Vec<KernelGrid>,
        field_axes: Option<crate::psf::field::FieldAxes>,
        mut settings: SplatSettings,
    ) -> crate::Result<Splatter> {
        settings.validate().map_err(crate::Error::Input)?;
        settings.texture_format = settings.texture_format.for_device(ctx.device_info().kind);
        if !ctx.can_write_images_without_format() {
            return Err(GpuError::Unsupported(
                "shaderStorageImageWriteWithoutFormat (needed to build the PSF texture)".into(),
            )
            .into());
        }
        let off_axis = field_axes.is_some();
        if off_axis && settings.tile_size > MAX_OFF_AXIS_TILE {
            // Measured on lavapipe: the four-node convolution at 32-pixel tiles (16 pixels per
            // thread) gives wrong tiles; 8 and 16 agree to the bit.
            return Err(crate::Error::input(format!(
                "--off-axis works with --tile-size 8 or 16 (asked {})",
                settings.tile_size
            )));
        }
        let blocks = atlas::block_kernels(&settings.merge, grid.max_radius_px);
        let layout = atlas::TextureLayout::new(&grid, field_axes.as_ref(), &blocks);
        layout.check(ctx, settings.texture_format.texel_bytes())?;
        let nodes: &[KernelGrid] = if node_grids.is_empty() {
            std::slice::from_ref(&grid)
        } else {
            &node_grids
        };
        let resident = nodes
            .iter()
            .map(|g| psf_texture::ResidentGrid::upload(ctx, g))
            .collect::<crate::gpu::GpuResult<Vec<_>>>()?;
        // Merging decides on the core radius: off axis the smallest over the nodes, so that a
        // block merges only where every node's kernel allows it.
        let core_radii = smallest_over_nodes(&grid, nodes, KernelSet::core_radii_px);
        let peak_radii = smallest_over_nodes(&grid, nodes, KernelSet::peak_radii_px);
        let texture = psf_texture::create_texture(ctx, layout.extent(), settings.texture_format)?;
        let field_table = field::FieldTable::new(ctx, field_axes.as_ref(), grid.objects.count)?;
        let atlas = Buffer::from_slice(ctx, "PSF texture atlas", &layout.atlas_words())?;
        // The layer kernels, on axis (off axis each node's kernel has its own radius, which
        // the four-node mix would blend at different sizes).
        let full =
            atlas::LayerLayout::new(grid.max_radius_px, 1, grid.objects.count as u32, &blocks);
        let layer_kernels = settings.layer_kernels && !off_axis && full.fits(ctx);
        let layer_layout = if layer_kernels {
            full
        } else {
            atlas::LayerLayout::new(0, 1, 1, &[])
        };
        let layer_texture =
            psf_texture::create_texture(ctx, layer_layout.extent(), settings.texture_format)?;
        // The same kernels in single floats, with the summed-area tables, where the layer
        // texture holds halves: a merged block's box is a difference of four corners of the
        // table, which halves would lose (single floats for every read cost the H200 15–30 %).
        let layer_sums = match settings.texture_format {
            psf_texture::PsfTextureFormat::Rgba32Float => None,
            _ => Some(psf_texture::create_texture(
                ctx,
                layer_layout.extent(),
                psf_texture::PsfTextureFormat::Rgba32Float,
            )?),
        };
        let layer_atlas = Buffer::from_slice(ctx, "layer texture atlas", &layer_layout.words())?;
        let radii = Buffer::new(
            ctx,
            "object radii",
            grid.objects.count as u64 * 32,
            Residency::Device,
        )?;
        Ok(Splatter {
            ctx: ctx.clone(),
            settings,
            resident,
            layout,
            atlas,
            layer_layout,
            layer_atlas,
            layer_texture,
            layer_sums,
            layer_kernels,
            field_table,
            node_grids,
            field_axes,
            texture,
            sampler: Sampler::linear(ctx, Edge::ZeroBorder)?,
            radii,
            radii_staging: Buffer::new(
                ctx,
                "object radii staging",
                grid.objects.count as u64 * 32,
                Residency::Upload,
            )?,
            texture_blend: None,
            last_lists: None,
            core_radii,
            peak_radii,
            frame: None,
            entries: None,
            passes: Passes::new(
                ctx,
                &passes::PassConfig {
                    tile_size: settings.tile_size,
                    off_axis,
                    per_fragment: settings.blend.mode
                        == crate::render::blend::BlendMode::PerFragment,
                    visit_slots: settings.convolve_walk.visits_on(ctx.device_info().kind),
                },
            )?,
            grid,
        })
    }

    /// Every field node's grid (on axis: the grid alone).
    pub(super) fn nodes(&self) -> &[KernelGrid] {
        if self.node_grids.is_empty() {
            std::slice::from_ref(&self.grid)
        } else {
            &self.node_grids
        }
    }

    /// The field lattice of off-axis kernels (None on axis).
    /// Per-frame resources for `width`×`height` with `layers` depth layers, made when the
    /// size or layer count changes and kept otherwise.
    pub(super) fn ensure_frame(
        &mut self,
        width: u32,
        height: u32,
        layers: u32,
    ) -> crate::Result<()> {
        if self
            .frame
            .as_ref()
            .is_some_and(|f| f.width == width && f.height == height && f.layers == layers)
        {
            return Ok(());
        }
        let ctx = &self.ctx;
        // every layer's pixels: the inputs and fragments are stacked layer under layer
        let pixels = u64::from(width) * u64::from(height) * u64::from(layers);
        let limit = binding_limit(ctx).min(self.settings.max_fragment_binding_bytes);
        let Some(per_chunk) = fragments::fragments_per_chunk(pixels, limit) else {
            return Err(crate::Error::input(format!(
                "a {width}×{height} frame with {layers} depth layer(s) needs {} MiB of fragments, over \
                 four of this device's {} MiB storage-buffer bindings; render at most {} pixels (all \
                 layers) per frame on this device",
                (pixels * FRAGMENT_BYTES) >> 20,
                limit >> 20,
                fragments::FRAGMENT_CHUNKS * (limit / FRAGMENT_BYTES)
            )));
        };
        let tile = self.settings.tile_size;
        let (tiles_x, tiles_y) = (width.div_ceil(tile), height.div_ceil(tile));
        let tiles = u64::from(tiles_x) * u64::from(tiles_y);
        let storage = ImageUsage::STORAGE;
        self.frame = Some(FrameResources {
            width,
            height,
            layers,
            tiles_x,
            tiles_y,
            color_in: Image::new_2d(
                ctx,
                "input colour",
                width,
                height * layers,
                TexelFormat::Rgba32Float,
                storage,
            )?,
            depth_in: Image::new_2d(
                ctx,
                "input depth",
                width,
                height * layers,
                TexelFormat::R32Float,
                storage,
            )?,
            color_out: Image::new_2d(
                ctx,
                "splat output",
                width,
                height,
                TexelFormat::Rgba32Float,
                storage,
            )?,
            fragments: fragments::FragmentStore::new(ctx, pixels, per_chunk)?,
            // per tile, then live fragments and the kernel evaluations' and texture reads' two
            // words each
            counts: Buffer::new(ctx, "tile counts", (tiles + 5) * 4, Residency::Device)?,
            cursors: Buffer::new(ctx, "tile cursors", tiles * 4, Residency::Device)?,
            offsets: Buffer::new(ctx, "tile offsets", (tiles + 1) * 4, Residency::Device)?,
            block_sums: Buffer::new(
                ctx,
                "scan block sums",
                tiles.div_ceil(1024) * 4,
                Residency::Device,
            )?,
            uniform: Buffer::new(
                ctx,
                "splat frame uniforms",
                FRAME_UNIFORM_BYTES,
                Residency::Upload,
            )?,
            staging: None,
            readback_color: Buffer::new(
                ctx,
                "output read-back",
                pixels / u64::from(layers) * 16,
                Residency::Readback,
            )?,
            // At most one band per tile row, plus the spare slot of a banded steady frame.
            band_table: Buffer::new(
                ctx,
                "band table",
                band_table_bytes(tiles_y + 1),
                Residency::Device,
            )?,
            readback_lists: Buffer::new(
                ctx,
                "list sizes read-back",
                band_header_at(tiles) + BAND_TABLE_HEADER_BYTES,
                Residency::Readback,
            )?,
        });
        self.texture_blend = None;
        self.last_lists = None;
        Ok(())
    }

    pub fn field_axes(&self) -> Option<&crate::psf::field::FieldAxes> {
        self.field_axes.as_ref()
    }
}

/// Per set and object distance, a per-kernel radius (`of`) at its smallest over the field nodes
/// (on axis, the grid's own), so that a block merges only where every node's kernel allows it.
fn smallest_over_nodes(
    grid: &KernelGrid,
    nodes: &[KernelGrid],
    of: fn(&KernelSet) -> Vec<[f32; 3]>,
) -> Vec<Vec<[f32; 3]>> {
    let mut radii: Vec<Vec<[f32; 3]>> = grid.sets.iter().map(of).collect();
    for g in nodes {
        for (mine, theirs) in radii.iter_mut().zip(&g.sets) {
            for (m, t) in mine.iter_mut().zip(of(theirs)) {
                for c in 0..3 {
                    m[c] = m[c].min(t[c]);
                }
            }
        }
    }
    radii
}
