// What the list passes (tile fill, tile sort, convolve) share: the band of tile rows they work
// on and the sort key of a list entry. A frame's bands are planned on the GPU from the prefix
// sum (glsl/render/splat/band_plan.comp) into the band table; each list pass reads its slot of
// that table (`BandPush` in src/render/splat/bands.rs: the slot and the list buffer's size).
// A slot past the planned bands is empty: it touches nothing. Tile sort needs nothing else, so
// it binds no frame block. Define BANDS_BINDING before including this file.
#ifndef OCULAR_BAND_GLSL
#define OCULAR_BAND_GLSL

layout(push_constant) uniform BandPush {
    uint slot;           // this dispatch's slot in the band table
    uint entry_capacity; // entries the list buffer holds: lists past it are not touched
} band_push;

// Header (band count, status, total entries, live fragments; kernel evaluations and texture
// reads, low and high words each), then two uvec4 per slot: (first tile, end tile, first
// entry, 0) and the indirect dispatch of the per-tile passes.
layout(std430, binding = BANDS_BINDING) readonly buffer BandTable {
    uvec4 band_header[2];
    uvec4 band_slots[];
};

struct Band {
    uint first_tile;     // tiles [first_tile, end_tile) are processed this band
    uint end_tile;
    uint first_entry;    // global list offset of the band's first entry
    uint entry_capacity;
};

Band band;

// Every list pass calls this first.
void load_band() {
    uvec4 range = band_slots[2u * band_push.slot];
    band = Band(range.x, range.y, range.z, band_push.entry_capacity);
}

// A tile's list lies wholly inside the list buffer (a frame recorded in one submission with a
// list buffer from an earlier frame may overflow it; the host then renders it again in bands).
bool list_fits(uint offset, uint count) {
    uint start = offset - band.first_entry;
    return start <= band.entry_capacity && count <= band.entry_capacity - start;
}

// Sort key of a list entry: depth bits (positive floats order like their bit patterns), then
// the fragment index, so that equal depths sort deterministically.
uvec2 entry_key(float depth, uint fragment) {
    return uvec2(floatBitsToUint(max(depth, 0.0)), fragment);
}

bool key_less(uvec2 a, uvec2 b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
}

#endif
