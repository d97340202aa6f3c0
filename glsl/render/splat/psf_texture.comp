#version 460
// Builds the per-frame PSF texture: kernels of up to four (pupil, focus) grid states blended
// with bilinear weights, laid out as layer = level·No + o, each level's (2r+1)² block (r its
// block radius) centred at texel Rmax, every other texel zero. Values are scaled by (2r+1)² so
// that half floats keep their precision (a kernel's mean texel becomes ~1); the convolution
// pass divides it back out.
#extension GL_GOOGLE_include_directive : require
#define FRAME_BINDING 5
#include "splat.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

// The same radius range (chunk) of four kernel sets; texels as packed RGB floats.
layout(std430, binding = 0) readonly buffer Set0 { float set0[]; };
layout(std430, binding = 1) readonly buffer Set1 { float set1[]; };
layout(std430, binding = 2) readonly buffer Set2 { float set2[]; };
layout(std430, binding = 3) readonly buffer Set3 { float set3[]; };
layout(binding = 4) writeonly uniform image3D psf_texture;

// One dispatch per chunk of radius levels and field node (`PsfTexturePush` in
// src/render/splat/psf_texture.rs). The tile code is column | row << 10 | data offset << 20
// (src/render/splat/field.rs). A tile is pitch = side + 2·offset texels square, its kernels
// start `offset` texels in: off axis a zero margin keeps bilinear reads at a kernel's edge out
// of the neighbouring tile.
layout(push_constant) uniform PsfTexturePush {
    uint first_level;    // the chunk's radius levels [first_level, end_level)
    uint end_level;
    uint first_texel;    // index of the chunk's first texel in a whole kernel set
    uint tile_code;
    vec4 corner_weights; // bilinear weights of the four grid states (unused ones zero)
} push;
#define WEIGHTS push.corner_weights
#define FIRST_LEVEL push.first_level
#define END_LEVEL push.end_level
#define FIRST_TEXEL push.first_texel
#define TILE_CODE push.tile_code

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

void main() {
    uint side = 2u * frame.max_radius + 1u;
    uint offset = TILE_CODE >> 20u;
    uint pitch = side + 2u * offset;
    uvec2 tile = uvec2(TILE_CODE & 1023u, (TILE_CODE >> 10u) & 1023u);
    uvec3 id = gl_GlobalInvocationID;
    uint layer = FIRST_LEVEL * frame.object_count + id.z;
    if (id.x >= pitch || id.y >= pitch || layer >= END_LEVEL * frame.object_count) {
        return;
    }
    uint level = layer / frame.object_count;
    uint r = level_block_radius(level);
    uint o = layer % frame.object_count;
    int dx = int(id.x) - int(offset + frame.max_radius);
    int dy = int(id.y) - int(offset + frame.max_radius);
    vec3 value = vec3(0.0);
    if (abs(dx) <= int(r) && abs(dy) <= int(r)) {
        uint kside = 2u * r + 1u;
        uint texel = frame.object_count * texels_below_level(level) + o * kside * kside
            + uint(dy + int(r)) * kside + uint(dx + int(r)) - FIRST_TEXEL;
        uint i = 3u * texel;
        value = WEIGHTS.x * vec3(set0[i], set0[i + 1u], set0[i + 2u]);
        if (WEIGHTS.y > 0.0) value += WEIGHTS.y * vec3(set1[i], set1[i + 1u], set1[i + 2u]);
        if (WEIGHTS.z > 0.0) value += WEIGHTS.z * vec3(set2[i], set2[i + 1u], set2[i + 2u]);
        if (WEIGHTS.w > 0.0) value += WEIGHTS.w * vec3(set3[i], set3[i + 1u], set3[i + 2u]);
        value *= float(kside * kside);
    }
    imageStore(psf_texture, ivec3(tile * pitch + id.xy, layer), vec4(value, 0.0));
}
