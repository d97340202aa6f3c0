#version 460
// Resolves the multisampled view-depth target to one depth per pixel without blending across
// edges: the nearest sample wins, so an edge pixel takes the depth of the nearest surface in
// it (a mixed colour never gets an in-between depth that belongs to no surface).

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2DMS view_depth;
layout(std430, binding = 1) writeonly buffer Depth { float depth_m[]; };

layout(push_constant) uniform Push {
    uint width;
    uint height;
    uint samples;
} push;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= push.width || p.y >= push.height) {
        return;
    }
    float d = texelFetch(view_depth, ivec2(p), 0).r;
    for (int s = 1; s < int(push.samples); ++s) {
        d = min(d, texelFetch(view_depth, ivec2(p), s).r);
    }
    depth_m[p.y * push.width + p.x] = d;
}
