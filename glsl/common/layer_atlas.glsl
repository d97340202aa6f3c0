// The layer texture (`LayerLayout` in src/render/splat/atlas.rs): per object distance (the
// layer) that distance's own kernel for this frame, all three channels in one texel, each at
// its channel's radius (glsl/render/splat/layer_kernels.comp writes it from the radius levels of
// the PSF texture). One region per field node; in it one slot per kind of fragment: the plain
// kernel, (2R+1)² texels inside a zero ring, and per merged block side s ≥ 4 the kernel summed
// over the block, (2R+s)² texels inside a zero ring (R: the grid's largest radius). Values are
// scaled by (2R+1)², as the PSF texture's are by their level's (2r+1)².
// Define LAYER_ATLAS_BINDING before including this file.
#ifndef OCULAR_LAYER_ATLAS_GLSL
#define OCULAR_LAYER_ATLAS_GLSL

layout(std430, binding = LAYER_ATLAS_BINDING) readonly buffer LayerAtlas {
    uvec4 layer_header;   // region width, region height, regions per row, R
    // per kind (0: plain; 1, 2, 3, 4: blocks of side 4, 8, 16, 32): the texel of its offset 0
    // within a region (plain: the centre texel; a block: the texel that begins there), its
    // block side (0: plain), 1 if the texture holds it
    uvec4 layer_kinds[5];
};

uint layer_kind(uint size) {
    return size < 4u ? 0u : uint(findMSB(size)) - 1u;
}

uvec2 layer_node_origin(uint node) {
    uint columns = layer_header.z;
    return uvec2(node % columns, node / columns) * layer_header.xy;
}

// Texture coordinate (texels, within a region) of kind k's offset 0.
vec2 layer_point(uint kind) {
    uvec4 k = layer_kinds[kind];
    return vec2(k.xy) + (k.z == 0u ? 0.5 : 0.0);
}

// Offsets strictly within this bound of kind k's offset 0 may be read.
float layer_bound(uint kind) {
    float r = float(layer_header.w);
    uint side = layer_kinds[kind].z;
    return side == 0u ? r + 1.0 : r + 0.5 * float(side) + 0.5;
}

// The (2R+1)² storage scale.
float layer_scale() {
    float k = float(2u * layer_header.w + 1u);
    return k * k;
}

#endif
