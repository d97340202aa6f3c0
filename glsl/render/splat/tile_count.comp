#version 460
// Counts, per screen tile, the fragments whose kernel can reach a pixel of that tile; the
// element after the last tile counts the live (not merged-away) fragments, the two after it
// (low and high words) the frame's kernel evaluations: the (pixel, fragment) pairs within
// reach, what the convolution's cost grows with, and the two after those the filtered texture
// reads the pixel walk makes for them (reads_per_evaluation; `ocular bench` reports both).
#extension GL_GOOGLE_include_directive : require
#define FRAME_BINDING 5
#include "splat.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

FRAGMENT_BUFFERS(0, 2, 3, 4, readonly)
FRAGMENT_LOAD
layout(std430, binding = 1) buffer Counts { uint counts[]; };
layout(std430, binding = 6) readonly buffer Field { vec4 field_header[2]; vec4 node_radii[]; };
#include "field.glsl"

shared uint live_in_group;
shared uint evaluations_in_group;
shared uint reads_in_group;

// Adds to the 64-bit sum in counts[at] (low word) and counts[at + 1] (high word): a carry
// into the high word when the low one wraps.
void add_wide(uint at, uint value) {
    uint before = atomicAdd(counts[at], value);
    if (before + value < before) {
        atomicAdd(counts[at + 1u], 1u);
    }
}

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        live_in_group = 0u;
        evaluations_in_group = 0u;
        reads_in_group = 0u;
    }
    barrier();
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x < frame.width && p.y < frame.height * frame.layers) {
        Fragment f = load_fragment(p.y * frame.width + p.x);
        if (f.size != 0u) {
            atomicAdd(live_in_group, 1u);
            Footprint fp = fragment_footprint(f);
            ivec4 pixels = fragment_pixels(f, fp);
            uint pairs = 0u;
            for (int py = pixels.y; py <= pixels.w; py++) {
                ivec2 x = footprint_columns(fp, f.center, py);
                pairs += uint(max(x.y - x.x + 1, 0));
            }
            if (pairs > 0u) {
                uvec4 nodes;
                vec4 weights;
                field_corners(f.center, nodes, weights);
                uint used = uint(weights.x > 0.0) + uint(weights.y > 0.0) + uint(weights.z > 0.0)
                          + uint(weights.w > 0.0);
                atomicAdd(evaluations_in_group, pairs);
                atomicAdd(reads_in_group, pairs * reads_per_evaluation(f, used));
            }
            int t = int(frame.tile_size);
            for (int ty = pixels.y / t; ty <= pixels.w / t && pixels.x <= pixels.z; ty++) {
                ivec2 tiles = footprint_tile_columns(fp, f.center, pixels, ty);
                for (int tx = tiles.x; tx <= tiles.y; tx++) {
                    atomicAdd(counts[uint(ty) * frame.tiles_x + uint(tx)], 1u);
                }
            }
        }
    }
    barrier();
    uint tiles = frame.tiles_x * frame.tiles_y;
    if (gl_LocalInvocationIndex == 0u && live_in_group > 0u) {
        atomicAdd(counts[tiles], live_in_group);
        add_wide(tiles + 1u, evaluations_in_group);
        add_wide(tiles + 3u, reads_in_group);
    }
}
