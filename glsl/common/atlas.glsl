// Where the PSF texture keeps each kernel (`TextureLayout` in src/render/splat/field.rs): an
// atlas with one region per field node (on axis one), regions row by row, each holding one
// block per radius level, (2r+1)² texels inside a zero ring; the layer is the object distance.
// A kernel of level l at node n is centred at kernel_centre(n, l). Reads must stay within
// r + 1 texels of that centre: past the ring lie other levels' blocks, or the gaps (zeroed
// once when the texture is first built).
// Define ATLAS_BINDING before including this file.
#ifndef OCULAR_ATLAS_GLSL
#define OCULAR_ATLAS_GLSL

layout(std430, binding = ATLAS_BINDING) readonly buffer Atlas {
    uvec4 atlas_header;    // region width, region height, regions per row, 0
    uvec4 level_centres[]; // per radius level: its kernel's centre texel within a region
};

uvec2 node_origin(uint node) {
    uint columns = atlas_header.z;
    return uvec2(node % columns, node / columns) * atlas_header.xy;
}

uvec2 kernel_centre(uint node, uint level) {
    return node_origin(node) + level_centres[level].xy;
}

#endif
