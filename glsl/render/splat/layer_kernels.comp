#version 460
// Builds the layer texture (glsl/common/layer_atlas.glsl) from the PSF texture's radius levels:
// per object distance o and channel c, the kernel at that distance's own radius r_c(o), which
// is the two radius levels around it mixed by the fraction between them, exactly what the
// convolution would read for a fragment at that distance. The convolution then makes one
// filtered read per (pixel, fragment) for all channels, where the levels need up to three,
// and the filter across layers blends two neighbouring distances' kernels, each at its own
// radius; the host picks this texture only where those radii differ by little
// (src/render/splat/layer_kernels.rs).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define ATLAS_BINDING 3
#define LAYER_ATLAS_BINDING 4
#define FRAME_BINDING 5
#include "splat.glsl"
#include "atlas.glsl"
#include "layer_atlas.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler3D psf_texture;
layout(binding = 1) writeonly uniform image3D layer_texture;
// The same slots in single floats, and the summed-area tables, summed in place (the layer
// texture itself where that is single floats: src/render/splat/construct.rs).
layout(binding = 6, rgba32f) coherent uniform image3D layer_sums;
layout(std430, binding = 2) readonly buffer Field { vec4 field_header[2]; vec4 node_radii[]; };

// One dispatch per field node and kind (`LayerKernelsPush` in src/render/splat/layer_kernels.rs).
layout(push_constant) uniform LayerKernelsPush {
    uint node;
    uint kind;  // 0: plain; 1 … 4: blocks of side 4 … 32; 5: the summed-area table
} push;

// Channel values of radius level `level`'s kernel for blocks of side s (0: plain) at integer
// texel offset u from its offset 0, object o, divided by the level's storage scale. A block
// side whose block-summed kernels start above this level reads the plain kernel (merging never
// makes such a block at this distance; a neighbouring distance's blend may touch it).
vec3 level_texel(uint level, uint s, ivec2 u, uint o) {
    if (level >= level_count()) {
        return vec3(0.0);
    }
    uint slot = kernel_slot(level, s);
    uint side = level_centres[slot].z;
    int r = int(level_block_radius(level));
    // Where the slot's kernel can be non-zero: |u| ≤ r for a plain kernel; for a block-summed
    // one, texel u holds offset u + ½, non-zero for u in [−(r + side/2), r + side/2 − 1].
    int lo = side == 0u ? -r : -(r + int(side / 2u));
    int hi = side == 0u ? r : r + int(side / 2u) - 1;
    if (any(lessThan(u, ivec2(lo))) || any(greaterThan(u, ivec2(hi)))) {
        return vec3(0.0);
    }
    ivec2 at = ivec2(node_origin(push.node) + level_centres[slot].xy) + u;
    float k = float(2 * r + 1);
    return texelFetch(psf_texture, ivec3(at, int(o)), 0).rgb / (k * k);
}

// Object o's kernel for blocks of side s (0: plain) at integer texel offset u from its offset
// 0, scaled by layer_scale: per channel the two radius levels around the distance's radius,
// mixed by the fraction between.
vec3 kind_value(ivec2 u, uint o, uint s) {
    // The distance's radius per channel, clamped as the fragments pass clamps it.
    vec3 radius = min(node_radii[push.node * frame.object_count + o].xyz,
                      vec3(float(frame.max_radius)));
    vec3 level = level_of_radius(radius);
    vec3 lo = floor(level);
    vec3 t = level - lo;
    vec3 value;
    [[unroll]] for (int c = 0; c < 3; c++) {
        float a = level_texel(uint(lo[c]), s, u, o)[c];
        value[c] = t[c] > 0.0 ? mix(a, level_texel(uint(lo[c]) + 1u, s, u, o)[c], t[c]) : a;
    }
    return value * layer_scale();
}

// The summed-area table of object o's plain kernel, one workgroup per object: texel (i, j)
// holds the sum of the texels at offsets x < i − R, y < j − R, i.e. the integral of the
// kernel taken as constant over each texel's unit square, up to the corner (i − R − ½,
// j − R − ½). The table is bilinear between its corners, so a filtered read at any point is
// that integral exactly. Rows are summed first (each into the texel below its own row), then
// columns, in place.
void summed_area(uint o) {
    int R = int(layer_header.w);
    int n = 2 * R + 2;
    uint t = gl_LocalInvocationIndex;
    ivec2 at = ivec2(layer_kinds[SAT_KIND].xy);
    for (int b = int(t); b < n - 1; b += 64) {
        vec3 sum = vec3(0.0);
        imageStore(layer_sums, ivec3(at + ivec2(0, b + 1), int(o)), vec4(0.0));
        for (int a = 0; a < n - 1; a++) {
            sum += kind_value(ivec2(a - R, b - R), o, 0u);
            imageStore(layer_sums, ivec3(at + ivec2(a + 1, b + 1), int(o)), vec4(sum, 0.0));
        }
    }
    memoryBarrierImage();
    barrier();
    for (int i = int(t); i < n; i += 64) {
        vec3 sum = vec3(0.0);
        imageStore(layer_sums, ivec3(at + ivec2(i, 0), int(o)), vec4(0.0));
        for (int j = 1; j < n; j++) {
            sum += imageLoad(layer_sums, ivec3(at + ivec2(i, j), int(o))).rgb;
            imageStore(layer_sums, ivec3(at + ivec2(i, j), int(o)), vec4(sum, 0.0));
        }
    }
}

void main() {
    uvec3 id = gl_GlobalInvocationID;
    if (push.kind == SAT_KIND) {
        summed_area(gl_WorkGroupID.z);
        return;
    }
    uvec4 kind = layer_kinds[push.kind];
    uint s = kind.z;
    uint R = layer_header.w;
    uint side = s == 0u ? 2u * R + 3u : 2u * R + s + 2u;
    if (id.x >= side || id.y >= side || id.z >= frame.object_count) {
        return;
    }
    // Offset of this texel from the slot's offset-0 texel; the outermost ring stays zero.
    int edge = s == 0u ? int(R) + 1 : int(R + s / 2u) + 1;
    ivec2 u = ivec2(id.xy) - ivec2(edge);
    vec3 value = vec3(0.0);
    if (id.x > 0u && id.y > 0u && id.x < side - 1u && id.y < side - 1u) {
        value = kind_value(u, id.z, s);
    }
    ivec2 at = ivec2(layer_node_origin(push.node) + kind.xy) + u;
    imageStore(layer_texture, ivec3(at, int(id.z)), vec4(value, 0.0));
    imageStore(layer_sums, ivec3(at, int(id.z)), vec4(value, 0.0));
}
