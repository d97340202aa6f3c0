#version 460
// Resolves the multisampled targets. Colour, on a GPU (push.colour): the mean of the samples,
// what a render pass's resolve writes, but spread over every compute unit, where an H100 or
// H200 runs a render pass's work on two TPCs (src/render/raster.rs). Depth, without blending
// across edges: the nearest sample
// wins, so an edge pixel takes the depth of the nearest surface in it (a mixed colour never
// gets an in-between depth that belongs to no surface). Mixed pixels (issue 51, docs/
// validation.md "Mixed pixels"): the samples within the blend's depth-group tolerance of the
// nearest one are the near surface's share of the pixel; the rest, what a silhouette lets
// through, is written apart (its mean colour and its nearest depth), so the splat and the
// reference can blur each part with its own kernel instead of the pixel's mean with the near
// one's.

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2DMS view_depth;
layout(std430, binding = 1) writeonly buffer Depth { float depth_m[]; };
layout(binding = 2) uniform sampler2DMS color_samples;
// rgb: the mean colour of the samples behind the near surface; a: the near surface's share
// of the pixel (1: the pixel shows one surface, and rgb is 0).
layout(std430, binding = 3) writeonly buffer Rest { vec4 rest[]; };
// The nearest depth among those samples (m); +∞ where there are none.
layout(std430, binding = 4) writeonly buffer RestDepth { float rest_depth_m[]; };
// The mean colour of the pixel's samples.
layout(binding = 5, rgba32f) writeonly uniform image2D color_out;

layout(push_constant) uniform Push {
    uint width;
    uint height;
    uint samples;
    // 1: write Rest and RestDepth (the visible layer); 0: depth only (a peeled layer)
    uint split;
    // the blend's depth-group tolerance (D): samples this close to the nearest one in
    // vergence belong to its surface
    float group_tolerance_d;
    // 1: write the colour's mean; 0: the render pass resolved it
    uint colour;
} push;

const int MAX_SAMPLES = 8;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= push.width || p.y >= push.height) {
        return;
    }
    uint i = p.y * push.width + p.x;
    int n = min(int(push.samples), MAX_SAMPLES);
    float d[MAX_SAMPLES];
    float nearest = 3.0e38;
    for (int s = 0; s < n; ++s) {
        d[s] = texelFetch(view_depth, ivec2(p), s).r;
        nearest = min(nearest, d[s]);
    }
    depth_m[i] = nearest;
    if (push.colour != 0u) {
        // summed in sample order and scaled by 1/n, as a render pass's average
        vec4 sum = vec4(0.0);
        for (int s = 0; s < n; ++s) {
            sum += texelFetch(color_samples, ivec2(p), s);
        }
        imageStore(color_out, ivec2(p), sum * (1.0 / float(n)));
    }
    if (push.split == 0u) {
        return;
    }
    // Vergence of the nearest sample; a sample belongs to its surface while its vergence is
    // within the tolerance (depths are positive: the clear value is the far plane).
    float v_near = 1.0 / max(nearest, 1e-6);
    vec3 rest_sum = vec3(0.0);
    float rest_depth = uintBitsToFloat(0x7f800000u);
    int near_count = 0;
    for (int s = 0; s < n; ++s) {
        if (v_near - 1.0 / max(d[s], 1e-6) <= push.group_tolerance_d) {
            near_count += 1;
        } else {
            rest_sum += texelFetch(color_samples, ivec2(p), s).rgb;
            rest_depth = min(rest_depth, d[s]);
        }
    }
    int rest_count = n - near_count;
    rest[i] = rest_count > 0 ? vec4(rest_sum / float(rest_count), float(near_count) / float(n))
                             : vec4(0.0, 0.0, 0.0, 1.0);
    rest_depth_m[i] = rest_depth;
}
