#version 460
// Counts, per screen tile, the fragments whose kernel can reach a pixel of that tile; the
// element after the last tile counts the live (not merged-away) fragments.
#extension GL_GOOGLE_include_directive : require
#define FRAME_BINDING 5
#include "splat.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

FRAGMENT_BUFFERS(0, 2, 3, 4, readonly)
FRAGMENT_LOAD
layout(std430, binding = 1) buffer Counts { uint counts[]; };

shared uint live_in_group;

void main() {
    if (gl_LocalInvocationIndex == 0u) live_in_group = 0u;
    barrier();
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x < frame.width && p.y < frame.height * frame.layers) {
        Fragment f = load_fragment(p.y * frame.width + p.x);
        if (f.size != 0u) {
            atomicAdd(live_in_group, 1u);
            ivec4 tiles = fragment_tiles(f);
            for (int ty = tiles.y; ty <= tiles.w; ty++) {
                for (int tx = tiles.x; tx <= tiles.z; tx++) {
                    atomicAdd(counts[uint(ty) * frame.tiles_x + uint(tx)], 1u);
                }
            }
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u && live_in_group > 0u) {
        atomicAdd(counts[frame.tiles_x * frame.tiles_y], live_in_group);
    }
}
