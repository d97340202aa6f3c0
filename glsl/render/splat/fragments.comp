#version 460
// One fragment per pixel: colour, distance along the ray, continuous index on the object-dioptre axis and the
// blur radius per channel, interpolated between the two neighbouring object distances (and,
// off axis, between the four neighbouring field nodes).
#extension GL_GOOGLE_include_directive : require
#define FRAME_BINDING 8
#include "splat.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) readonly uniform image2D color_in;
layout(binding = 1, r32f) readonly uniform image2D depth_in;
// Natural radius per object distance, per channel (xyz), of this frame's blended kernels.
layout(std430, binding = 2) readonly buffer Radii { vec4 radii[]; };
FRAGMENT_BUFFERS(3, 5, 6, 7, writeonly)
FRAGMENT_STORE
// Per field node, the same radii (on axis: one node, equal to `radii`).
layout(std430, binding = 4) readonly buffer Field { vec4 field_header[2]; vec4 node_radii[]; };
#include "field.glsl"

void main() {
    uvec2 g = gl_GlobalInvocationID.xy;
    if (g.x >= frame.width || g.y >= frame.height * frame.layers) {
        return;
    }
    // Layers are stacked downwards: row g.y is row p.y of layer g.y / height.
    uint layer = g.y / frame.height;
    uvec2 p = uvec2(g.x, g.y - layer * frame.height);
    vec3 color = imageLoad(color_in, ivec2(g)).rgb;
    float depth = imageLoad(depth_in, ivec2(g)).r;
    // Infinite, missing or non-positive depth is optical infinity (0 D). Depth is along the
    // view axis; light reaches the eye with the vergence of the distance along the ray.
    bool finite_depth = depth > 0.0 && !isinf(depth) && !isnan(depth);
    vec2 u = (vec2(p) + 0.5 - 0.5 * vec2(frame.width, frame.height)) / frame.focal_px;
    float ray = frame.wide_field != 0u ? sqrt(1.0 + dot(u, u)) : 1.0;
    float distance = depth * ray;
    float dioptre = finite_depth ? 1.0 / distance : 0.0;
    float last = float(frame.object_count - 1u);
    float index = clamp((dioptre - frame.dioptre_min) / frame.dioptre_step, 0.0, last);
    uint i0 = uint(floor(index));
    uint i1 = min(i0 + 1u, frame.object_count - 1u);
    // Off axis, the radius is the bilinear mix over the four field nodes around the pixel.
    uvec4 nodes;
    vec4 weights;
    field_corners(vec2(p) + 0.5, nodes, weights);
    vec3 radius = vec3(0.0);
    for (uint k = 0u; k < 4u; k++) {
        uint b = nodes[k] * frame.object_count;
        radius += weights[k] * mix(node_radii[b + i0].xyz, node_radii[b + i1].xyz, index - float(i0));
    }

    Fragment f;
    f.color = color;
    f.depth = finite_depth ? distance : 3.0e38;
    f.radius = min(radius, vec3(float(frame.max_radius)));
    f.index = index;
    f.center = vec2(p) + 0.5;
    // A hidden layer is empty where its depth is infinite: no fragment (the visible layer's
    // infinite depth is the background at optical infinity).
    f.size = layer > 0u && !finite_depth ? 0u : 1u;
    if (layer > 0u && f.size != 0u) {
        // Near the frame's border the visible layer's coverage falls short because nothing
        // lies beyond the frame, not because its edge lets light by: a hidden fragment there
        // would fill that gap with what no pupil point sees (e.g. geometry under a floor).
        // Keep it only farther from the border than the visible surface's own blur radius.
        float d0 = imageLoad(depth_in, ivec2(p)).r;
        bool finite0 = d0 > 0.0 && !isinf(d0) && !isnan(d0);
        float v0 = finite0 ? 1.0 / (d0 * ray) : 0.0;
        float i0f = clamp((v0 - frame.dioptre_min) / frame.dioptre_step, 0.0, last);
        uint j0 = uint(floor(i0f));
        uint j1 = min(j0 + 1u, frame.object_count - 1u);
        float r0 = min(max(mix(radii[j0].y, radii[j1].y, i0f - float(j0)), 0.0), float(frame.max_radius));
        vec2 c = vec2(p) + 0.5;
        float border = min(min(c.x, float(frame.width) - c.x), min(c.y, float(frame.height) - c.y));
        if (border < r0 + 1.0) {
            f.size = 0u;
        }
    }
    f.dioptre = dioptre;
    store_fragment(g.y * frame.width + g.x, f);
}
