#version 460
// Appends every fragment to the list of each tile of the current band that its kernel can
// reach, at the tile's offset from the prefix sum. The fill order depends on scheduling; the
// sort pass makes the lists deterministic.
#extension GL_GOOGLE_include_directive : require
#define FRAME_BINDING 8
#define BANDS_BINDING 4
#include "splat.glsl"
#include "band.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

FRAGMENT_BUFFERS(0, 5, 6, 7, readonly)
FRAGMENT_LOAD
layout(std430, binding = 1) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = 2) buffer Cursors { uint cursors[]; };
layout(std430, binding = 3) writeonly buffer Entries { uvec2 entries[]; };

void main() {
    load_band();
    if (band.first_tile >= band.end_tile) {
        return; // an empty slot of the band table
    }
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= frame.width || p.y >= frame.height * frame.layers) {
        return;
    }
    uint index = p.y * frame.width + p.x;
    Fragment f = load_fragment(index);
    if (f.size == 0u) {
        return;
    }
    Footprint fp = fragment_footprint(f);
    ivec4 pixels = fragment_pixels(f, fp);
    if (pixels.x > pixels.z) {
        return;
    }
    // Bands are whole tile rows: clip the rows to the band's.
    int t = int(frame.tile_size);
    int band_y0 = int(band.first_tile / frame.tiles_x);
    int band_y1 = int((band.end_tile - 1u) / frame.tiles_x);
    for (int ty = max(pixels.y / t, band_y0); ty <= min(pixels.w / t, band_y1); ty++) {
        ivec2 tiles = footprint_tile_columns(fp, f.center, pixels, ty);
        for (int tx = tiles.x; tx <= tiles.y; tx++) {
            uint tile = uint(ty) * frame.tiles_x + uint(tx);
            uint slot = atomicAdd(cursors[tile], 1u);
            uint at = offsets[tile] - band.first_entry + slot;
            if (at < band.entry_capacity) {
                entries[at] = entry_key(f.depth, index);
            }
        }
    }
}
