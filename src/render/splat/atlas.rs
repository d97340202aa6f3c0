//! The PSF texture's layout: an atlas with one region per node of the field lattice
//! ([`crate::psf::field_kernels`]; on axis a single node), each holding one slot per radius
//! level (and the block-summed kernels merging reads), and one layer per object distance
//! (glsl/common/atlas.glsl is the shaders' side).

use crate::gpu::Context;
use crate::psf::field::FieldAxes;
use crate::psf::kernels::{level_block_radius, level_count, level_of_radius, KernelGrid};

/// Zero texels around each level's block: bilinear reads at a kernel's edge reach one texel
/// past it, and that texel must be zero. The convolution reads within the ring, but the
/// filter's subtexel rounding may touch the texel beyond it with weight zero, so the atlas's
/// gaps are cleared to zero once (a NaN there would survive the zero weight).
const BLOCK_MARGIN: u32 = 1;

/// The off-axis PSF texture may always take this much (bytes), where one allocation can hold
/// it: lavapipe's whole heap, and what every earlier release allowed.
const FIELD_TEXTURE_FLOOR_BYTES: u64 = 2 << 30;

/// Largest off-axis PSF texture (bytes) on a device with `device_local_bytes` of local memory
/// and `max_allocation_bytes` per allocation: a quarter of the local memory (the frame's lists
/// and images need the rest), never less than [`FIELD_TEXTURE_FLOOR_BYTES`], and never more
/// than one allocation. Memory stays bounded whatever the lattice, and a large GPU is not held
/// to a small one's budget (an H100's 80 GiB took the astigmatic eye's 3.5 GiB texture, which
/// a fixed 2 GiB refused).
pub(super) fn field_texture_limit_bytes(device_local_bytes: u64, max_allocation_bytes: u64) -> u64 {
    (device_local_bytes / 4)
        .max(FIELD_TEXTURE_FLOOR_BYTES)
        .min(max_allocation_bytes)
}

/// Where every kernel lies in the PSF texture. Each node's region holds one block per radius
/// level, (2r+1)² kernel texels inside a zero ring, and, where merging makes blocks of 4×4
/// pixels and up, each such side's block-summed kernels ([`BlockKernels`]); all packed in
/// shelves. The layer is the object distance, so the linear filter across layers blends
/// neighbouring distances of one level at one place, as the convolution wants. Regions tile
/// the texture row by row. A level's block takes only its own size, where a layout of equal
/// layers (the paper's, and ocular's before) gives every level the largest one's: at 41 px
/// that is 37 % of the memory.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct TextureLayout {
    /// Field nodes (h-major) and object distances.
    pub nodes: u32,
    pub objects: u32,
    /// A region's size in texels, and regions per texture row.
    pub region: [u32; 2],
    pub columns: u32,
    /// Per kernel slot (the radius levels, then each block side's levels): its centre texel
    /// within a region and its block side (0: a plain kernel).
    pub slots: Vec<Slot>,
    /// Per block side with kernels in the atlas: the side, its first level, and the slot of
    /// that level.
    pub blocks: Vec<(BlockKernels, u32)>,
}

/// One kernel's place in a region. A plain kernel's offset 0 is the centre of texel `centre`;
/// a block-summed kernel has an even side, so its offset 0 is the corner where texel
/// `centre` begins (texel `centre` holds offset +½).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Slot {
    pub level: u32,
    pub block_side: u32,
    pub centre: [u32; 2],
}

impl Slot {
    /// Side of the kernel's texels with their zero ring.
    fn side(&self) -> u32 {
        let r = level_block_radius(self.level);
        if self.block_side == 0 {
            2 * (r + BLOCK_MARGIN) + 1
        } else {
            2 * (r + BLOCK_MARGIN) + self.block_side
        }
    }
}

/// Kernels summed over a merged block of `side` × `side` pixels, for the radius levels from
/// `first_level` on. A block of 4×4 pixels or more spreads each pixel's light by the same
/// kernel from that pixel's own position; what reaches a pixel is the kernel summed over the
/// block's positions, which one read of such a kernel gives exactly (light conserved, the
/// shape kept, however large the block against the blur). A 2×2 block needs none: half a
/// pixel off the grid, the bilinear read of the plain kernel is that sum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockKernels {
    pub side: u32,
    pub first_level: u32,
}

/// The block sides merging can make under `merge` with kernels up to `max_radius` px, and
/// from which level on each needs its kernels: a block of side s merges only when every
/// kernel in it is at least max(min radius, blur per block · s) (glsl/render/splat/merge.comp),
/// so no smaller level is ever read for it (one level of margin below, against rounding).
pub fn block_kernels(merge: &super::MergeSettings, max_radius: u32) -> Vec<BlockKernels> {
    let levels = level_count(max_radius);
    (2..=merge.levels)
        .filter_map(|k| {
            let side = 1u32 << k;
            let smallest = f64::from(merge.min_radius_px.max(merge.blur_per_block * side as f32));
            if smallest > f64::from(max_radius) {
                return None; // no kernel is wide enough for this block to merge
            }
            let first_level = (level_of_radius(smallest.max(0.0)).floor() as u32).saturating_sub(1);
            (first_level < levels).then_some(BlockKernels { side, first_level })
        })
        .collect()
}

/// Shelf packing of slots, largest first, into rows `width` texels wide: each slot's centre
/// and the height used.
fn pack_slots(slots: &mut [Slot], width: u32) -> u32 {
    let mut order: Vec<usize> = (0..slots.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(slots[i].side()), i));
    let (mut x, mut y, mut shelf) = (0u32, 0u32, 0u32);
    for i in order {
        let side = slots[i].side();
        if x + side > width && x > 0 {
            y += shelf;
            (x, shelf) = (0, 0);
        }
        // A plain kernel's centre texel has `half` texels on either side; an even block's
        // offset 0 lies `half` texels from its slot's edge, at the start of texel x + half.
        slots[i].centre = [x + side / 2, y + side / 2];
        x += side;
        shelf = shelf.max(side);
    }
    y + shelf
}

impl TextureLayout {
    pub fn new(
        grid: &KernelGrid,
        field: Option<&FieldAxes>,
        blocks: &[BlockKernels],
    ) -> TextureLayout {
        let nodes = field.map_or(1, |f| (f.h_deg.len() * f.v_deg.len()) as u32);
        TextureLayout::with(grid.max_radius_px, nodes, grid.objects.count as u32, blocks)
    }

    /// The layout of `nodes` regions of kernels up to `max_radius` px at `objects` distances,
    /// with block-summed kernels for `blocks`.
    fn with(max_radius: u32, nodes: u32, objects: u32, blocks: &[BlockKernels]) -> TextureLayout {
        let levels = level_count(max_radius);
        let mut slots: Vec<Slot> = (0..levels)
            .map(|level| Slot {
                level,
                block_side: 0,
                centre: [0, 0],
            })
            .collect();
        let mut placed = Vec::new();
        for b in blocks {
            placed.push((*b, slots.len() as u32));
            slots.extend((b.first_level..levels).map(|level| Slot {
                level,
                block_side: b.side,
                centre: [0, 0],
            }));
        }
        // The region width whose packing wastes least, and of those within 3 % of it the most
        // square (long thin regions would run into the device's side limit first).
        let widest = slots.iter().map(Slot::side).max().unwrap_or(1);
        let total: u32 = slots.iter().map(Slot::side).sum();
        let mut trial = slots.clone();
        let packed: Vec<(u32, u32)> = (widest..=total)
            .map(|w| (w, pack_slots(&mut trial, w)))
            .collect();
        let area = |&(w, h): &(u32, u32)| u64::from(w) * u64::from(h);
        let least = packed.iter().map(area).min().unwrap_or(0);
        let best = packed
            .iter()
            .filter(|p| area(p) * 100 <= least * 103)
            .min_by_key(|&&(w, h)| (w.max(h), w))
            .map_or(widest, |p| p.0);
        let height = pack_slots(&mut slots, best);
        let columns = square_columns(nodes, [best, height]);
        TextureLayout {
            nodes,
            objects,
            region: [best, height],
            columns,
            slots,
            blocks: placed,
        }
    }

    pub fn extent(&self) -> [u32; 3] {
        regions_extent(self.nodes, self.columns, self.region, self.objects)
    }

    /// Bytes of the texture at `texel_bytes` per texel.
    pub fn bytes(&self, texel_bytes: u64) -> u64 {
        texture_bytes(self.extent(), texel_bytes)
    }

    /// Texel of the kernel centre of `level` at field node `node`.
    pub fn centre(&self, node: u32, level: u32) -> [u32; 2] {
        self.slot_centre(node, level as usize)
    }

    /// Texel of slot `slot`'s centre at field node `node` (see [`Slot`]).
    pub fn slot_centre(&self, node: u32, slot: usize) -> [u32; 2] {
        let c = self.slots[slot].centre;
        [
            (node % self.columns) * self.region[0] + c[0],
            (node / self.columns) * self.region[1] + c[1],
        ]
    }

    /// The Atlas buffer the PSF-texture and convolution passes read (glsl/common/atlas.glsl):
    /// the region, regions per row; per block side 4, 8, 16, 32 the slot of level 0 were its
    /// kernels to start there (0: none), and its first level; then each slot's centre and
    /// block side.
    pub fn atlas_words(&self) -> Vec<[u32; 4]> {
        let mut base = [0u32; 4];
        let mut first = [0u32; 4];
        for (b, slot) in &self.blocks {
            let k = b.side.trailing_zeros() as usize - 2;
            base[k] = slot - b.first_level;
            first[k] = b.first_level;
        }
        let mut words = vec![
            [self.region[0], self.region[1], self.columns, 0],
            base,
            first,
        ];
        words.extend(
            self.slots
                .iter()
                .map(|s| [s.centre[0], s.centre[1], s.block_side, 0]),
        );
        words
    }

    /// A texture this device can create: every side within its 3D-image limit, and off axis
    /// no larger than [`field_texture_limit_bytes`].
    pub fn check(&self, ctx: &Context, texel_bytes: u64) -> crate::Result<()> {
        let bytes = self.bytes(texel_bytes);
        let info = ctx.device_info();
        let limit =
            field_texture_limit_bytes(info.device_local_mib << 20, info.max_allocation_mib << 20);
        let largest = level_block_radius(level_count_of(&self.slots) - 1);
        if self.nodes > 1 && bytes > limit {
            return Err(crate::Error::input(format!(
                "--off-axis: the PSF texture for {} field nodes with kernels up to {largest} px \
                 would take {} MiB, over the {} MiB this device allows (a quarter of its memory, \
                 at least 2048 MiB, at most one allocation); lower the largest radius (smaller \
                 pupil, field of view or resolution)",
                self.nodes,
                bytes >> 20,
                limit >> 20
            )));
        }
        let side_limit = ctx.limits().max_image_dimension3_d;
        let [x, y, z] = self.extent();
        if x.max(y).max(z) > side_limit {
            return Err(crate::Error::input(format!(
                "the PSF texture would be {x}×{y}×{z} texels ({} field node(s), kernels up to \
                 {largest} px), over this device's 3D-image limit of {side_limit} per side; lower \
                 the kernels' largest radius (a smaller field of view or pupil) or the field nodes",
                self.nodes
            )));
        }
        Ok(())
    }
}

/// The kind of the layer texture's summed-area tables (`LayerLayout::kinds`; SAT_KIND in
/// glsl/common/layer_atlas.glsl).
pub(super) const SAT_KIND: usize = 5;

/// Where each object distance's own kernel lies in the layer texture
/// (glsl/common/layer_atlas.glsl): one region per field node, and in it one slot per kind of
/// fragment, side by side: the plain kernel ((2R+1)² texels inside a zero ring, R the grid's
/// largest radius), per block side s of `blocks` the block-summed one ((2R+s)² inside a
/// ring), and the plain kernel's summed-area table ((2R+2)² corners, read clamped), which
/// merged blocks read in the wide field. The layer is the object distance, as in the PSF
/// texture.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct LayerLayout {
    pub nodes: u32,
    pub objects: u32,
    /// R: every slot holds kernels up to this radius.
    pub max_radius: u32,
    pub region: [u32; 2],
    pub columns: u32,
    /// Per kind (0: plain, then the block sides 4, 8, 16, 32): the texel of its offset 0
    /// within a region and its block side, if the texture holds it; kind 5 ([`SAT_KIND`]):
    /// the plain kernel's summed-area table, (2R+2)² corners, and the texel of its first.
    pub kinds: [Option<([u32; 2], u32)>; 6],
}

impl LayerLayout {
    pub fn new(max_radius: u32, nodes: u32, objects: u32, blocks: &[BlockKernels]) -> LayerLayout {
        let r = max_radius;
        let mut kinds = [None; 6];
        let mut x = 0;
        let mut height = 0;
        let sides = std::iter::once(0).chain(blocks.iter().map(|b| b.side));
        for side in sides {
            // A plain kernel's offset 0 is its centre texel, r + 1 from the slot's edge; a
            // block's is the texel that begins at it, r + s/2 + 1 from the edge.
            let width = layer_slot_width(r, side);
            let edge = if side == 0 { r + 1 } else { r + side / 2 + 1 };
            let kind = if side == 0 {
                0
            } else {
                side.trailing_zeros() as usize - 1
            };
            kinds[kind] = Some(([x + edge, edge], side));
            x += width;
            height = height.max(width);
        }
        // Read with clamped coordinates (it is constant past the kernel): no zero ring.
        kinds[SAT_KIND] = Some(([x, 0], 0));
        x += 2 * r + 2;
        height = height.max(2 * r + 2);
        let columns = square_columns(nodes, [x, height]);
        LayerLayout {
            nodes,
            objects,
            max_radius,
            region: [x, height],
            columns,
            kinds,
        }
    }

    pub fn extent(&self) -> [u32; 3] {
        regions_extent(self.nodes, self.columns, self.region, self.objects)
    }

    pub fn bytes(&self, texel_bytes: u64) -> u64 {
        texture_bytes(self.extent(), texel_bytes)
    }

    /// The LayerAtlas buffer: the region, regions per row and R; per kind its offset-0 texel,
    /// block side and whether it is held.
    pub fn words(&self) -> Vec<[u32; 4]> {
        let mut words = vec![[
            self.region[0],
            self.region[1],
            self.columns,
            self.max_radius,
        ]];
        words.extend(self.kinds.iter().map(|k| match k {
            Some((at, side)) => [at[0], at[1], *side, 1],
            None => [0, 0, 0, 0],
        }));
        words
    }

    /// Whether this device can create the texture (every side within its 3D-image limit).
    pub fn fits(&self, ctx: &Context) -> bool {
        let [x, y, z] = self.extent();
        x.max(y).max(z) <= ctx.limits().max_image_dimension3_d
    }
}

/// Texels across a layer-texture slot of kernels up to radius `r` for blocks of `side` (0:
/// plain), its zero ring included.
pub(super) fn layer_slot_width(r: u32, side: u32) -> u32 {
    if side == 0 {
        2 * r + 3
    } else {
        2 * r + side + 2
    }
}

/// Regions per texture row for `nodes` regions of size `region`: the arrangement closest to
/// square (long thin textures would run into the device's side limit first).
fn square_columns(nodes: u32, region: [u32; 2]) -> u32 {
    (1..=nodes)
        .min_by_key(|&c| (c * region[0]).max(nodes.div_ceil(c) * region[1]))
        .unwrap_or(1)
}

/// A texture of `nodes` regions, `columns` to a row, one layer per object distance.
fn regions_extent(nodes: u32, columns: u32, region: [u32; 2], objects: u32) -> [u32; 3] {
    [
        columns * region[0],
        nodes.div_ceil(columns) * region[1],
        objects,
    ]
}

fn texture_bytes([x, y, z]: [u32; 3], texel_bytes: u64) -> u64 {
    u64::from(x) * u64::from(y) * u64::from(z) * texel_bytes
}

/// Radius levels of a layout's slots (the plain ones come first, one per level).
fn level_count_of(slots: &[Slot]) -> u32 {
    slots.iter().filter(|s| s.block_side == 0).count() as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::psf::kernels::level_radius_px;

    /// Every slot's kernel with its zero ring lies inside its node's region and overlaps no
    /// other, for every node, on and off axis, with and without block-summed kernels.
    #[test]
    fn blocks_tile_their_regions_without_overlap() {
        let lod = |levels| crate::render::splat::MergeSettings {
            levels,
            blur_per_block: 2.0,
            min_radius_px: 0.0,
            ..Default::default()
        };
        let seed = crate::render::splat::MergeSettings {
            levels: 5,
            blur_per_block: 0.0,
            ..Default::default()
        };
        for (max_radius, nodes, merge) in [
            (1, 1, lod(0)),
            (2, 1, lod(5)),
            (3, 1, seed),
            (9, 1, lod(5)),
            (9, 1, seed),
            (41, 104, lod(0)),
            (64, 12, lod(5)),
        ] {
            let blocks = block_kernels(&merge, max_radius);
            let l = TextureLayout::with(max_radius, nodes, 5, &blocks);
            let [x, y, z] = l.extent();
            assert_eq!(z, 5);
            let mut covered = vec![false; (x * y) as usize];
            for node in 0..nodes {
                let (rx, ry) = (
                    (node % l.columns) * l.region[0],
                    (node / l.columns) * l.region[1],
                );
                for (i, slot) in l.slots.iter().enumerate() {
                    let half = slot.side() / 2;
                    // texels before and after the centre texel
                    let (lo, hi) = (half, slot.side() - 1 - half);
                    let [cx, cy] = l.slot_centre(node, i);
                    let at = format!("Rmax {max_radius}, slot {i} {slot:?}");
                    assert!(cx >= rx + lo && cx + hi < rx + l.region[0], "{at}");
                    assert!(cy >= ry + lo && cy + hi < ry + l.region[1], "{at}");
                    for ty in cy - lo..=cy + hi {
                        for tx in cx - lo..=cx + hi {
                            let i = (ty * x + tx) as usize;
                            assert!(!covered[i], "overlap at {tx},{ty} ({at})");
                            covered[i] = true;
                        }
                    }
                }
            }
            let used = covered.iter().filter(|&&c| c).count() as f64;
            eprintln!(
                "Rmax {max_radius}, {nodes} node(s), blocks {blocks:?}: {x}×{y}, {:.0} % of the \
                 texels used",
                100.0 * used / f64::from(x * y)
            );
        }
    }

    /// Level of detail at k = 2 merges a block of side s only over kernels of at least 2s px:
    /// the atlas holds 4×4 kernels from 8 px and 8×8 from 16 px, none wider than the largest
    /// kernel; the seed paper's rule (5 px, any side) holds every side from 5 px.
    #[test]
    fn block_kernels_start_where_merging_can() {
        let lod = crate::render::splat::MergeSettings {
            levels: 5,
            blur_per_block: 2.0,
            min_radius_px: 0.0,
            ..Default::default()
        };
        let b = block_kernels(&lod, 16);
        assert_eq!(b.len(), 2, "{b:?}");
        assert_eq!((b[0].side, level_radius_px(b[0].first_level)), (4, 7.0));
        assert_eq!((b[1].side, level_radius_px(b[1].first_level)), (8, 15.0));
        let seed = crate::render::splat::MergeSettings {
            levels: 3,
            blur_per_block: 0.0,
            ..Default::default()
        };
        let b = block_kernels(&seed, 11);
        assert_eq!(b.iter().map(|b| b.side).collect::<Vec<_>>(), [4, 8]);
        assert!(b.iter().all(|b| level_radius_px(b.first_level) == 4.0));
        // All five levels at k = 1: every side up to 32, each from the radius of its own side
        // (and the 5 px minimum).
        let all = crate::render::splat::MergeSettings {
            levels: 5,
            blur_per_block: 1.0,
            ..Default::default()
        };
        let b = block_kernels(&all, 40);
        let starts: Vec<(u32, f64)> = b
            .iter()
            .map(|b| (b.side, level_radius_px(b.first_level)))
            .collect();
        assert_eq!(starts, [(4, 4.0), (8, 7.0), (16, 15.0), (32, 31.0)]);
        // 2×2 blocks only need no block kernels; the default (k = 2) stores the sides whose
        // kernels fit under Rmax 40: 4, 8 and 16 (a 32×32 block needs 64 px).
        let two_by_two = crate::render::splat::MergeSettings {
            levels: 1,
            ..Default::default()
        };
        assert!(block_kernels(&two_by_two, 40).is_empty());
        let sides: Vec<u32> = block_kernels(&crate::render::splat::MergeSettings::default(), 40)
            .iter()
            .map(|b| b.side)
            .collect();
        assert_eq!(sides, [4, 8, 16]);
    }

    /// The atlas against the equal-layer layout it replaced, (2·Rmax + 1 + 2)² texels per
    /// level and object: the astigmatic eye's 1280×720 off-axis texture (13 × 8 nodes,
    /// kernels up to 41 px, 13 object distances), refused at 3577 MiB (the figure the old
    /// layout's error gave), fits lavapipe's 2 GiB.
    #[test]
    fn the_atlas_takes_a_fraction_of_equal_layers() {
        let (max_radius, nodes, objects) = (41u32, 104u32, 13u32);
        let l = TextureLayout::with(max_radius, nodes, objects, &[]);
        let pitch = u64::from(2 * max_radius + 3);
        let equal_layers =
            u64::from(nodes) * pitch * pitch * u64::from(level_count(max_radius) * objects) * 8;
        let atlas = l.bytes(8);
        eprintln!(
            "atlas {} MiB, equal layers {} MiB",
            atlas >> 20,
            equal_layers >> 20
        );
        // measured: 1316 MiB against 3577 MiB (37 %)
        assert!(10 * atlas < 4 * equal_layers, "{atlas} vs {equal_layers}");
        assert!(atlas < 2 << 30);
        let [x, y, _] = l.extent();
        assert!(x <= 4096 && y <= 4096, "{x}×{y}");
    }

    #[test]
    fn the_field_texture_bound_follows_the_device() {
        const GIB: u64 = 1 << 30;
        // lavapipe: a 2 GiB heap that one allocation may fill keeps the 2 GiB of before.
        assert_eq!(field_texture_limit_bytes(2 * GIB, 2 * GIB), 2 * GIB);
        // An 80 GiB GPU: a quarter of its memory, so the astigmatic eye's 3.5 GiB fits.
        assert_eq!(field_texture_limit_bytes(80 * GIB, u64::MAX), 20 * GIB);
        assert!(field_texture_limit_bytes(80 * GIB, u64::MAX) > 3577 << 20);
        // Never past one allocation, even where the floor or the quarter would allow it.
        assert_eq!(field_texture_limit_bytes(80 * GIB, 4 * GIB), 4 * GIB);
        assert_eq!(field_texture_limit_bytes(GIB, GIB / 2), GIB / 2);
        // A small GPU gets the floor, not a quarter of its memory.
        assert_eq!(field_texture_limit_bytes(4 * GIB, 8 * GIB), 2 * GIB);
    }

    /// The layer texture's slots lie side by side within their region, each with its ring,
    /// and a block kind's offset 0 sits where the convolution's bound expects it.
    #[test]
    fn layer_slots_fit_their_region() {
        let blocks = [
            BlockKernels {
                side: 4,
                first_level: 10,
            },
            BlockKernels {
                side: 16,
                first_level: 30,
            },
        ];
        let l = LayerLayout::new(20, 1, 161, &blocks);
        assert_eq!(l.kinds[0], Some(([21, 21], 0)));
        // plain: 43 texels wide; then the 4-block: 46 wide, offset 0 at 20 + 2 + 1 = 23 in
        assert_eq!(l.kinds[1], Some(([43 + 23, 23], 4)));
        assert_eq!(l.kinds[2], None);
        assert_eq!(l.kinds[3], Some(([43 + 46 + 29, 29], 16)));
        // the summed-area table: 42 corners from its first texel, after the blocks
        assert_eq!(l.kinds[SAT_KIND], Some(([43 + 46 + 58, 0], 0)));
        assert_eq!(l.region, [43 + 46 + 58 + 42, 58]);
        assert_eq!(l.extent(), [189, 58, 161]);
        for (at, side) in l.kinds[..SAT_KIND].iter().flatten() {
            let half = 20 + side / 2 + 1;
            assert!(at[0] >= half && at[1] >= half);
            assert!(at[1] + half <= l.region[1] + u32::from(*side == 0));
        }
        let many = LayerLayout::new(20, 12, 161, &[]);
        let [x, y, _] = many.extent();
        assert!(x.max(y) <= 4 * (43 + 42), "{x}×{y}");
    }
}
