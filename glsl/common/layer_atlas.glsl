// The layer texture (`LayerLayout` in src/render/splat/atlas.rs): per object distance (the
// layer) that distance's own kernel for this frame, all three channels in one texel, each at
// its channel's radius (glsl/render/splat/layer_kernels.comp writes it from the radius levels of
// the PSF texture). One region per field node; in it one slot per kind of fragment: the plain
// kernel, (2R+1)² texels inside a zero ring, and per merged block side s ≥ 4 the kernel summed
// over the block, (2R+s)² texels inside a zero ring (R: the grid's largest radius); on axis also
// the plain kernel's summed-area table, (2R+2)² corners. Values are scaled by (2R+1)², as the
// PSF texture's are by their level's (2r+1)²; single floats (src/render/splat/construct.rs).
// Define LAYER_ATLAS_BINDING before including this file, and LAYER_TEXTURE_BINDING and
// LAYER_SUMS_BINDING to sample the texture and its single-float copy (the wide field's block
// reads).
#ifndef OCULAR_LAYER_ATLAS_GLSL
#define OCULAR_LAYER_ATLAS_GLSL

layout(std430, binding = LAYER_ATLAS_BINDING) readonly buffer LayerAtlas {
    uvec4 layer_header;   // region width, region height, regions per row, R
    // per kind (0: plain; 1, 2, 3, 4: blocks of side 4, 8, 16, 32): the texel of its offset 0
    // within a region (plain: the centre texel; a block: the texel that begins there), its
    // block side (0: plain), 1 if the texture holds it; kind 5 (SAT_KIND): the plain kernel's
    // summed-area table, from the texel of its first corner
    uvec4 layer_kinds[6];
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

// The push constant's kind of the dispatch that builds the summed-area tables (layer_box).
const uint SAT_KIND = 5u;

// The (2R+1)² storage scale.
float layer_scale() {
    float k = float(2u * layer_header.w + 1u);
    return k * k;
}

#ifdef LAYER_TEXTURE_BINDING
layout(binding = LAYER_TEXTURE_BINDING) uniform sampler3D layer_texture;
// The same slots in single floats, with the summed-area tables (the layer texture itself
// where that is single floats): src/render/splat/construct.rs.
layout(binding = LAYER_SUMS_BINDING) uniform sampler3D layer_sums;

// A merged block in the wide field, with the depth-group blend. Its s × s pixels lie J·δ
// apart in kernel space (J = c_t·I + (c_r − c_t)·e·eᵀ, the local scale's map), not δ, so the
// block-summed kernels, which assume δ, misplace its edge pixels by (1 − c_r)·s/2. Instead:
// a 2×2 block reads its four pixels' kernels where they lie, exactly what the
// pixels would read; a larger block reads its box (layer_box), the kernel's mean over J's
// diagonal times the block: a bilinear read is the integral of the kernel taken as constant
// per texel over a unit square, so the pixels' reads sum to about that integral over the
// parallelogram J·block, and the box is that parallelogram without its shear. When: block_reads
// (splat.glsl).

// Kind k's value at kernel offset d in the region at `origin`, at texture layer coordinate
// `layer`, divided by layer_scale; zero past the kind's bound.
vec3 layer_read(uint k, vec2 d, vec2 origin, float layer) {
    if (any(greaterThanEqual(abs(d), vec2(layer_bound(k))))) {
        return vec3(0.0);
    }
    vec3 extent = vec3(textureSize(layer_texture, 0));
    vec3 uvw = vec3((origin + layer_point(k) + d) / extent.xy, layer);
    return textureLod(layer_texture, uvw, 0.0).rgb / layer_scale();
}

// Texture coordinate (texels, within region 0) at which the summed-area table holds corner 0:
// corner x (kernel offset, −R − ½ … R + ½) lies at this plus x.
vec2 sat_point() {
    return vec2(layer_kinds[SAT_KIND].xy) + float(layer_header.w) + 1.0;
}

// The plain kernel's mean over the box of half-sides h centred at kernel offset u, at texture
// layer coordinate `layer`, divided by layer_scale like every layer read. Four filtered reads
// of the summed-area table, clamped to it: the table is bilinear between its corners (exact at
// any point) and constant past the kernel.
vec3 layer_box(vec2 u, vec2 h, float layer) {
    float b = float(layer_header.w) + 0.5;
    vec2 lo = clamp(u - h, vec2(-b), vec2(b));
    vec2 hi = clamp(u + h, vec2(-b), vec2(b));
    vec2 extent = vec2(textureSize(layer_sums, 0).xy);
    vec2 p = sat_point();
    vec3 s = textureLod(layer_sums, vec3((p + hi) / extent, layer), 0.0).rgb
           - textureLod(layer_sums, vec3((p + vec2(lo.x, hi.y)) / extent, layer), 0.0).rgb
           - textureLod(layer_sums, vec3((p + vec2(hi.x, lo.y)) / extent, layer), 0.0).rgb
           + textureLod(layer_sums, vec3((p + lo) / extent, layer), 0.0).rgb;
    return s / (4.0 * h.x * h.y * layer_scale());
}

#endif

#endif
