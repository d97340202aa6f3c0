// Where the PSF texture keeps each kernel (`TextureLayout` in src/render/splat/atlas.rs): an
// atlas with one region per field node (on axis one), regions row by row, each holding one
// slot per radius level, (2r+1)² texels inside a zero ring, and where merging makes blocks of
// 4×4 pixels and up, per such side s the levels' kernels summed over the block, (2r+s)² texels
// inside a zero ring; the layer is the object distance. Reads must stay strictly within
// slot_bound of a kernel's offset 0: past the ring lie other slots, or the gaps (zeroed once
// when the texture is first built).
// Define ATLAS_BINDING before including this file.
#ifndef OCULAR_ATLAS_GLSL
#define OCULAR_ATLAS_GLSL

layout(std430, binding = ATLAS_BINDING) readonly buffer Atlas {
    uvec4 atlas_header;    // region width, region height, regions per row, 0
    uvec4 block_base;      // per block side 4, 8, 16, 32: level l's slot is base + l (0: none)
    uvec4 block_first;     // per block side: the first level it holds
    uvec4 level_centres[]; // per slot: its centre texel within a region, its block side (0: plain)
};

uvec2 node_origin(uint node) {
    uint columns = atlas_header.z;
    return uvec2(node % columns, node / columns) * atlas_header.xy;
}

// The slot of radius level `level` for a fragment of block side `size`. A merged block of
// 4×4 pixels and up reads its side's block-summed kernel, which merge.comp guarantees the
// atlas holds (it merges only over kernels at least as wide as the first level held).
uint kernel_slot(uint level, uint size) {
    if (size < 4u) {
        return level;
    }
    uint b = uint(findMSB(size)) - 2u;
    return block_base[b] != 0u && level >= block_first[b] ? block_base[b] + level : level;
}

// Texture coordinate (texels, within a region) of slot `slot`'s offset 0: a plain kernel's
// centre texel's centre; a block-summed kernel's (even side) the corner where its centre
// texel begins.
vec2 slot_point(uint slot) {
    uvec4 c = level_centres[slot];
    return vec2(c.xy) + (c.z == 0u ? 0.5 : 0.0);
}

// Offsets of slot `slot` (radius level `level`) strictly within this bound of its offset 0
// may be read: the kernel's texels and its zero ring.
float slot_bound(uint slot, uint level) {
    float r = float(level_block_radius(level));
    uint side = level_centres[slot].z;
    return side == 0u ? r + 1.0 : r + 0.5 * float(side) + 0.5;
}

uvec2 kernel_centre(uint node, uint level) {
    return node_origin(node) + level_centres[level].xy;
}

#endif
