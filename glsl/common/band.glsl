// What the list passes (tile fill, tile sort, convolve) share: the band of tile rows they work
// on, as their push constants (`BandPush` in src/render/splat/bands.rs; a frame whose lists
// exceed one binding or the memory budget runs band after band with the same frame uniforms),
// and the sort key of a list entry. Tile sort needs nothing else, so it binds no frame block.
#ifndef OCULAR_BAND_GLSL
#define OCULAR_BAND_GLSL

layout(push_constant) uniform BandPush {
    uint first_tile;     // tiles [first_tile, end_tile) are processed this band
    uint end_tile;
    uint first_entry;    // global list offset of the band's first entry
    uint entry_capacity; // entries the list buffer holds: lists past it are not touched
} band;

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
