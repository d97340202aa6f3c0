#version 460
// Plans the frame's bands on the GPU from the exact list sizes (the prefix sum), so that a
// frame whose lists exceed one band is still one submission: whole tile rows are packed
// greedily into bands of at most `capacity` entries, the same rule as `plan_bands` in
// src/render/splat/bands.rs, and each band is written to its slot of the band table with the
// indirect dispatch of the per-tile passes (tile sort, convolve). Slots past the planned
// bands are left empty. The host reads the header back: status 0 means every tile was in
// some slot; 1 means the frame needed more bands than slots were recorded, 2 that one row of
// tiles needs more than the whole list buffer (the host then plans the frame itself). With a
// status other than 0 every slot is empty, so nothing reads past the list buffer.
// The rows (at most 2048) are walked by one invocation: sequential, and a few microseconds.

layout(local_size_x = 1) in;

layout(push_constant) uniform BandPlanPush {
    uint tiles_x;  // tiles per row
    uint tiles;    // tiles in the frame (whole rows)
    uint capacity; // entries the list buffer holds
    uint slots;    // slots recorded in this submission
} plan;

// tiles + 5: live fragments, then the frame's kernel evaluations and texture reads (low and
// high words each)
layout(std430, binding = 0) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 1) readonly buffer Offsets { uint offsets[]; }; // tiles + 1: total last
layout(std430, binding = 2) writeonly buffer BandTable {
    uvec4 band_header[2];
    uvec4 band_slots[];
};

// One workgroup per tile, folded into two dimensions past the per-axis dispatch limit that
// every device has (the per-tile passes unfold it and skip the excess).
const uint AXIS = 65535u;

void write_slot(uint k, uint first_tile, uint end_tile) {
    uint n = end_tile - first_tile;
    band_slots[2u * k] = uvec4(first_tile, end_tile, offsets[first_tile], 0u);
    band_slots[2u * k + 1u] = n == 0u ? uvec4(0u, 0u, 1u, 0u)
                                      : uvec4(min(n, AXIS), (n + AXIS - 1u) / AXIS, 1u, 0u);
}

void main() {
    uint tx = max(plan.tiles_x, 1u);
    uint rows = plan.tiles / tx;
    uint bands = 0u;
    uint status = 0u;
    uint start_row = 0u;
    uint entries = 0u;
    for (uint row = 0u; row < rows; row++) {
        uint row_entries = offsets[(row + 1u) * tx] - offsets[row * tx];
        if (row_entries > plan.capacity) {
            status = 2u;
            break;
        }
        if (row_entries > plan.capacity - entries && row > start_row) {
            if (bands < plan.slots) {
                write_slot(bands, start_row * tx, row * tx);
            }
            bands++;
            start_row = row;
            entries = 0u;
        }
        entries += row_entries;
    }
    if (status == 0u) {
        if (bands < plan.slots) {
            write_slot(bands, start_row * tx, rows * tx);
        }
        bands++;
        if (bands > plan.slots) {
            status = 1u;
        }
    }
    uint first_empty = status == 0u ? bands : 0u;
    for (uint k = first_empty; k < plan.slots; k++) {
        write_slot(k, plan.tiles, plan.tiles);
    }
    band_header[0] = uvec4(bands, status, offsets[plan.tiles], counts[plan.tiles]);
    band_header[1] = uvec4(counts[plan.tiles + 1u], counts[plan.tiles + 2u],
                           counts[plan.tiles + 3u], counts[plan.tiles + 4u]);
}
