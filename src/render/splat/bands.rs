//! Bands: when a frame's tile lists exceed what one binding (or the memory budget) holds, the
//! screen is processed in bands of whole tile rows, planned from the exact per-tile counts.
//! The GPU plans every frame's bands (glsl/render/splat/band_plan.comp, into the band table
//! below); [`plan_bands`] is the same rule on the host, which sizes the list buffer and the
//! slots of a frame the GPU could not plan, and whose band count the GPU's must then match.

use crate::gpu::shader_block;

use super::ENTRY_BYTES;

/// A range of whole tile rows processed together, and where its entries start in the global
/// (prefix-sum) numbering.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Band {
    pub first_tile: u32,
    pub end_tile: u32,
    pub first_entry: u32,
    pub entries: u64,
}

shader_block! {
    /// Push constants of the list passes (tile fill, tile sort, convolve): which slot of the band
    /// table they work on. Mirrors `BandPush` in glsl/common/band.glsl.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
    pub(crate) struct BandPush {
        pub slot: u32,
        /// Entries the list buffer holds: lists past it are not touched (the host re-plans).
        pub entry_capacity: u32,
    }
}

/// One band slot as the list passes record it: its push constants and the list buffer.
#[derive(Clone, Copy)]
pub(super) struct BandSlot<'a> {
    pub push: BandPush,
    pub entries: &'a crate::gpu::Buffer,
}

/// The band table the GPU plans (glsl/render/splat/band_plan.comp): a 32-byte header (band
/// count, status, total entries, live fragments, kernel evaluations and texture reads as two words
/// each),
/// then 32 bytes per slot, the band's range and the indirect dispatch of the per-tile passes.
pub(crate) const BAND_TABLE_HEADER_BYTES: u64 = 32;
const BAND_SLOT_BYTES: u64 = 32;

/// Bytes of a band table with `slots` slots.
pub(crate) fn band_table_bytes(slots: u32) -> u64 {
    BAND_TABLE_HEADER_BYTES + u64::from(slots) * BAND_SLOT_BYTES
}

/// Where slot `slot`'s indirect dispatch (three u32) lies in the band table.
pub(crate) fn dispatch_offset(slot: u32) -> u64 {
    BAND_TABLE_HEADER_BYTES + u64::from(slot) * BAND_SLOT_BYTES + 16
}

/// The band table's header as the host reads it back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PlannedBands {
    /// Bands the frame needs at the list buffer's size.
    pub bands: u32,
    /// 0: every tile lies in a recorded slot; 1: more bands than slots; 2: one row of tiles
    /// needs more entries than the list buffer holds.
    pub status: u32,
    pub total_entries: u32,
    pub live_fragments: u32,
    /// (pixel, fragment) pairs within reach: the convolution's work.
    pub kernel_evaluations: u64,
    /// Filtered texture reads the pixel walk makes for them (reads_per_evaluation in
    /// glsl/common/splat.glsl).
    pub texture_reads: u64,
}

impl PlannedBands {
    pub fn from_header(header: &[u32]) -> PlannedBands {
        PlannedBands {
            bands: header[0],
            status: header[1],
            total_entries: header[2],
            live_fragments: header[3],
            kernel_evaluations: u64::from(header[4]) | (u64::from(header[5]) << 32),
            texture_reads: u64::from(header[6]) | (u64::from(header[7]) << 32),
        }
    }

    /// Every band was recorded: the frame is complete.
    pub fn complete(&self) -> bool {
        self.status == 0
    }
}

/// Splits the screen into bands of whole tile rows whose lists fit `capacity` entries.
pub(crate) fn plan_bands(counts: &[u32], tiles_x: u32, capacity: u64) -> crate::Result<Vec<Band>> {
    let rows = counts.len() as u32 / tiles_x.max(1);
    let mut bands = Vec::new();
    let mut start_row = 0u32;
    let mut first_entry = 0u64;
    let mut entries = 0u64;
    for row in 0..rows {
        let row_entries: u64 = counts[(row * tiles_x) as usize..((row + 1) * tiles_x) as usize]
            .iter()
            .map(|&c| u64::from(c))
            .sum();
        if row_entries > capacity {
            return Err(crate::Error::input(format!(
                "one row of tiles needs {row_entries} list entries ({} MiB), over the {} MiB a band may use on this device; \
                 lower the frame size, enable fragment merging, or use a larger tile size",
                (row_entries * ENTRY_BYTES) >> 20,
                (capacity * ENTRY_BYTES) >> 20
            )));
        }
        if entries + row_entries > capacity && row > start_row {
            bands.push(Band {
                first_tile: start_row * tiles_x,
                end_tile: row * tiles_x,
                first_entry: first_entry as u32,
                entries,
            });
            start_row = row;
            first_entry += entries;
            entries = 0;
        }
        entries += row_entries;
    }
    bands.push(Band {
        first_tile: start_row * tiles_x,
        end_tile: rows * tiles_x,
        first_entry: first_entry as u32,
        entries,
    });
    Ok(bands)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_every_row_once_and_respect_capacity() {
        let tiles_x = 3;
        let counts = [5, 5, 5, 1, 1, 1, 9, 0, 0, 2, 2, 2];
        // Rows hold 15, 3, 9 and 6 entries.
        let bands = plan_bands(&counts, tiles_x, 15).unwrap();
        assert_eq!(
            bands
                .iter()
                .map(|b| (b.first_tile, b.end_tile, b.first_entry))
                .collect::<Vec<_>>(),
            [(0, 3, 0), (3, 9, 15), (9, 12, 27)]
        );
        let bands = plan_bands(&counts, tiles_x, 20).unwrap();
        assert_eq!(
            bands
                .iter()
                .map(|b| (b.first_tile, b.end_tile, b.first_entry))
                .collect::<Vec<_>>(),
            [(0, 6, 0), (6, 12, 18)]
        );
        assert!(bands.iter().all(|b| b.entries <= 20));
        assert_eq!(plan_bands(&counts, tiles_x, 1000).unwrap().len(), 1);
        let err = plan_bands(&counts, tiles_x, 14).unwrap_err().to_string();
        assert!(err.contains("one row of tiles needs 15"), "{err}");
    }
}
