#version 460
// Builds the per-frame PSF texture: kernels of up to four (pupil, focus) grid states blended
// with bilinear weights, written into the atlas (glsl/common/atlas.glsl): each radius level's
// (2r+1)² block, r its block radius, around its centre in the node's region, inside a ring of
// zeros, at the layer of its object distance. Values are scaled by (2r+1)² so that half floats
// keep their precision (a kernel's mean texel becomes ~1); the convolution pass divides it
// back out. A dispatch with a block side s ≥ 4 writes instead each level's kernel summed over
// the s × s pixels of a merged block, divided by s² (the convolution multiplies the block's
// pixel count back), at half-pixel offsets (2r+s)² around the block's centre.
#extension GL_GOOGLE_include_directive : require
#define FRAME_BINDING 6
#define ATLAS_BINDING 5
#include "splat.glsl"
#include "atlas.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

// The same radius range (chunk) of four kernel sets; texels as packed RGB floats.
layout(std430, binding = 0) readonly buffer Set0 { float set0[]; };
layout(std430, binding = 1) readonly buffer Set1 { float set1[]; };
layout(std430, binding = 2) readonly buffer Set2 { float set2[]; };
layout(std430, binding = 3) readonly buffer Set3 { float set3[]; };
layout(binding = 4) writeonly uniform image3D psf_texture;

// One dispatch per chunk of radius levels and field node (`PsfTexturePush` in
// src/render/splat/psf_texture.rs): invocation (x, y) of layer z writes texel (x, y) of the
// square of level first_level + z / No, object z % No, that holds the block and its ring.
layout(push_constant) uniform PsfTexturePush {
    uint first_level;    // the chunk's radius levels [first_level, end_level)
    uint end_level;
    uint first_texel;    // index of the chunk's first texel in a whole kernel set
    uint node;           // the field node (h-major; on axis 0)
    vec4 corner_weights; // bilinear weights of the four grid states (unused ones zero)
    uint block_side;     // 0: the plain kernels; 4, 8, 16, 32: block-summed kernels
    uint pad0;           // to the Rust struct's 48 bytes
    uint pad1;
    uint pad2;
} push;
#define WEIGHTS push.corner_weights
#define FIRST_LEVEL push.first_level
#define END_LEVEL push.end_level
#define FIRST_TEXEL push.first_texel

uint texels_below(uint r) {
    return r * (4u * r * r - 1u) / 3u;
}

// Texels in the blocks of all levels below `level` (psf::kernels::texels_below_level).
uint fine_texels_below(uint level) {
    uint n = 0u;
    for (uint l = 0u; l < level; l++) {
        uint side = 2u * level_block_radius(l) + 1u;
        n += side * side;
    }
    return n;
}

uint texels_below_level(uint level) {
    if (level <= FINE_LEVELS + 1u) {
        return fine_texels_below(level);
    }
    return fine_texels_below(FINE_LEVELS + 1u) + texels_below(level_block_radius(level))
        - texels_below(FINE_UNTIL_PX + 1u);
}

// The blended kernel texel at integer offset (dx, dy) of level `level` (radius r) and object o.
vec3 kernel_texel(uint level, uint r, uint o, int dx, int dy) {
    uint kside = 2u * r + 1u;
    uint texel = frame.object_count * texels_below_level(level) + o * kside * kside
        + uint(dy + int(r)) * kside + uint(dx + int(r)) - FIRST_TEXEL;
    uint i = 3u * texel;
    vec3 value = WEIGHTS.x * vec3(set0[i], set0[i + 1u], set0[i + 2u]);
    if (WEIGHTS.y > 0.0) value += WEIGHTS.y * vec3(set1[i], set1[i + 1u], set1[i + 2u]);
    if (WEIGHTS.z > 0.0) value += WEIGHTS.z * vec3(set2[i], set2[i + 1u], set2[i + 2u]);
    if (WEIGHTS.w > 0.0) value += WEIGHTS.w * vec3(set3[i], set3[i + 1u], set3[i + 2u]);
    return value;
}

// Texel (x, y) of level `level`'s block-summed kernel for blocks of side s with its ring:
// offset (x, y) − (r + s/2 + 1) + ½ from the block's centre; the block's pixels sit at
// ±½ … ±(s − 1)/2, so pixel j of a row meets the kernel at integer offset x − j − r − 1.
void write_block(uint level, uint o, uint s) {
    uint slot = kernel_slot(level, s);
    if (slot == level) {
        return; // this side holds no kernel of this level
    }
    uvec3 id = gl_GlobalInvocationID;
    uint r = level_block_radius(level);
    uint side = 2u * r + s + 2u;
    if (id.x >= side || id.y >= side) {
        return;
    }
    int edge = int(r + s / 2u + 1u);
    vec3 value = vec3(0.0);
    if (id.x > 0u && id.y > 0u && id.x < side - 1u && id.y < side - 1u) {
        // Block pixels j whose kernel offset lies in [−r, r]: j in [x − 2r − 1, x − 1].
        int x0 = max(int(id.x) - 2 * int(r) - 1, 0);
        int x1 = min(int(id.x) - 1, int(s) - 1);
        int y0 = max(int(id.y) - 2 * int(r) - 1, 0);
        int y1 = min(int(id.y) - 1, int(s) - 1);
        for (int jy = y0; jy <= y1; jy++) {
            for (int jx = x0; jx <= x1; jx++) {
                value += kernel_texel(level, r, o, int(id.x) - jx - int(r) - 1,
                                      int(id.y) - jy - int(r) - 1);
            }
        }
        float kside = float(2u * r + 1u);
        value *= kside * kside / float(s * s);
    }
    ivec2 at = ivec2(node_origin(push.node) + level_centres[slot].xy)
             + ivec2(id.xy) - ivec2(edge);
    imageStore(psf_texture, ivec3(at, int(o)), vec4(value, 0.0));
}

void main() {
    uvec3 id = gl_GlobalInvocationID;
    uint level = FIRST_LEVEL + id.z / frame.object_count;
    if (level >= END_LEVEL) {
        return;
    }
    uint o = id.z % frame.object_count;
    if (push.block_side >= 4u) {
        write_block(level, o, push.block_side);
        return;
    }
    uint r = level_block_radius(level);
    // the block and its one-texel ring of zeros
    if (id.x > 2u * r + 2u || id.y > 2u * r + 2u) {
        return;
    }
    int dx = int(id.x) - int(r + 1u);
    int dy = int(id.y) - int(r + 1u);
    vec3 value = vec3(0.0);
    if (abs(dx) <= int(r) && abs(dy) <= int(r)) {
        uint kside = 2u * r + 1u;
        value = kernel_texel(level, r, o, dx, dy) * float(kside * kside);
    }
    ivec2 at = ivec2(kernel_centre(push.node, level)) + ivec2(dx, dy);
    imageStore(psf_texture, ivec3(at, int(o)), vec4(value, 0.0));
}
