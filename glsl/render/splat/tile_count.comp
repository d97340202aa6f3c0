#version 460
// Counts, per screen tile, the fragments whose kernel can reach a pixel of that tile; the
// element after the last tile counts the live (not merged-away) fragments, the two after it
// (low and high words) the frame's kernel evaluations: the (pixel, fragment) pairs within
// reach, what the convolution's cost grows with (`ocular bench` reports them).
#extension GL_GOOGLE_include_directive : require
#define FRAME_BINDING 5
#include "splat.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

FRAGMENT_BUFFERS(0, 2, 3, 4, readonly)
FRAGMENT_LOAD
layout(std430, binding = 1) buffer Counts { uint counts[]; };

shared uint live_in_group;
shared uint evaluations_in_group;

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        live_in_group = 0u;
        evaluations_in_group = 0u;
    }
    barrier();
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x < frame.width && p.y < frame.height * frame.layers) {
        Fragment f = load_fragment(p.y * frame.width + p.x);
        if (f.size != 0u) {
            atomicAdd(live_in_group, 1u);
            ivec4 pixels = fragment_pixels(f);
            if (pixels.x <= pixels.z) {
                atomicAdd(evaluations_in_group,
                          uint(pixels.z - pixels.x + 1) * uint(pixels.w - pixels.y + 1));
            }
            ivec4 tiles = tiles_of_pixels(pixels);  // the reach once per fragment
            for (int ty = tiles.y; ty <= tiles.w; ty++) {
                for (int tx = tiles.x; tx <= tiles.z; tx++) {
                    atomicAdd(counts[uint(ty) * frame.tiles_x + uint(tx)], 1u);
                }
            }
        }
    }
    barrier();
    uint tiles = frame.tiles_x * frame.tiles_y;
    if (gl_LocalInvocationIndex == 0u && live_in_group > 0u) {
        atomicAdd(counts[tiles], live_in_group);
        // a 64-bit sum from two words: carry into the high word when the low one wraps
        uint before = atomicAdd(counts[tiles + 1u], evaluations_in_group);
        if (before + evaluations_in_group < before) {
            atomicAdd(counts[tiles + 2u], 1u);
        }
    }
}
