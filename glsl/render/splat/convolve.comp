#version 460
// Convolution: one workgroup per tile walks the tile's sorted list front to back, streaming
// fragments through shared memory in batches, and blends each fragment's kernel into every
// pixel of the tile: per channel, C += (1 − A)·w·c and A += (1 − A)·w; the output is C / A.
// The kernel weight w comes from two trilinear lookups in the PSF texture (floor and ceiling
// radius; the layer axis blends the two neighbouring object distances), mixed by frac(radius).
#extension GL_GOOGLE_include_directive : require
#include "splat.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler3D psf_texture;
layout(std430, binding = 1) readonly buffer Fragments { Fragment fragments[]; };
layout(std430, binding = 2) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 3) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = 4) readonly buffer Entries { uvec2 entries[]; };
layout(binding = 5, rgba32f) writeonly uniform image2D color_out;

const uint MAX_PIXELS_PER_THREAD = 16u; // 32-pixel tiles on 8×8 threads
shared Fragment batch[64];

float kernel_weight(vec2 d, float r, float index, int channel) {
    float side = float(2u * frame.max_radius + 1u);
    float layers = float(frame.object_count * (frame.max_radius + 1u));
    vec3 uvw = vec3((float(frame.max_radius) + 0.5 + d) / side,
                    (r * float(frame.object_count) + index + 0.5) / layers);
    float k = 2.0 * r + 1.0;
    return textureLod(psf_texture, uvw, 0.0)[channel] / (k * k);
}

void main() {
    uint tile = frame.band_first_tile + gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
    if (tile >= frame.band_end_tile) {
        return;
    }
    uint tx = tile % frame.tiles_x;
    uint ty = tile / frame.tiles_x;
    uint n = counts[tile];
    uint base = offsets[tile] - frame.band_first_entry;
    uint per_axis = frame.tile_size / 8u;
    uint local_index = gl_LocalInvocationIndex;

    vec3 C[MAX_PIXELS_PER_THREAD];
    vec3 A[MAX_PIXELS_PER_THREAD];
    for (uint q = 0u; q < MAX_PIXELS_PER_THREAD; q++) {
        C[q] = vec3(0.0);
        A[q] = vec3(0.0);
    }

    for (uint start = 0u; start < n; start += 64u) {
        if (start + local_index < n) {
            batch[local_index] = fragments[entries[base + start + local_index].y];
        }
        barrier();
        uint batch_size = min(64u, n - start);
        for (uint j = 0u; j < batch_size; j++) {
            Fragment f = batch[j];
            float reach = fragment_reach(f);
            float exponent = float(f.size * f.size);
            for (uint q = 0u; q < per_axis * per_axis; q++) {
                uvec2 pixel = uvec2(tx, ty) * frame.tile_size + gl_LocalInvocationID.xy
                    + 8u * uvec2(q % per_axis, q / per_axis);
                vec2 d = vec2(pixel) + 0.5 - f.center;
                if (abs(d.x) > reach || abs(d.y) > reach) {
                    continue;
                }
                for (int c = 0; c < 3; c++) {
                    float radius = f.radius[c];
                    float r0 = floor(radius);
                    float r1 = ceil(radius);
                    float w = kernel_weight(d, r0, f.index, c);
                    if (r1 > r0) {
                        w = mix(w, kernel_weight(d, r1, f.index, c), radius - r0);
                    }
                    if (f.size > 1u) {
                        // A merged block covers size² pixels' worth of the same light.
                        w = 1.0 - pow(max(1.0 - w, 0.0), exponent);
                    }
                    C[q][c] += (1.0 - A[q][c]) * w * f.color[c];
                    A[q][c] += (1.0 - A[q][c]) * w;
                }
            }
        }
        barrier();
    }

    for (uint q = 0u; q < per_axis * per_axis; q++) {
        uvec2 pixel = uvec2(tx, ty) * frame.tile_size + gl_LocalInvocationID.xy
            + 8u * uvec2(q % per_axis, q / per_axis);
        if (pixel.x < frame.width && pixel.y < frame.height) {
            vec3 a = A[q];
            vec3 color = vec3(a.r > 0.0 ? C[q].r / a.r : 0.0,
                              a.g > 0.0 ? C[q].g / a.g : 0.0,
                              a.b > 0.0 ? C[q].b / a.b : 0.0);
            imageStore(color_out, ivec2(pixel), vec4(color, 1.0));
        }
    }
}
