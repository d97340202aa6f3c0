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

layout(push_constant) uniform FragmentsPush {
    // 1: a hidden fragment keeps only the light that passes the nearer surfaces on its way to
    // the pupil (pupil_visibility); 0: all of it, away from the frame's border
    uint pupil_visibility;
    float focus_d;           // the vergence the eye is focused on (D): its kernels are smallest there
    float parallax_px_per_d; // screen parallax per dioptre of a ray through the pupil's edge
                             // (pupil radius × focal length in pixels)
} push;

const float PI = 3.14159265358979;

// Vergence of the visible surface (layer 0) at pixel q, along its ray; 0 at infinity.
float visible_vergence(ivec2 q) {
    float d = imageLoad(depth_in, q).r;
    if (!(d > 0.0) || isinf(d) || isnan(d)) {
        return 0.0;
    }
    vec2 u = (vec2(q) + 0.5 - 0.5 * vec2(frame.width, frame.height)) / frame.focal_px;
    float ray = frame.wide_field != 0u ? sqrt(1.0 + dot(u, u)) : 1.0;
    return 1.0 / (d * ray);
}

// Which rays from a hidden point at pixel p (vergence v_hidden) reach the pupil past the
// visible surface. A ray to the pupil point at ρ·a in direction e, seen from the pupil's
// centre, leaves the point's pixel along e while its vergence grows by 1/(ρ·a·f) per pixel
// (a: pupil radius, f: focal length in pixels). It starts behind the visible surface and
// reaches the eye in front of everything, so it crosses the surface's depth map somewhere:
// across a jump of more than the group tolerance it passed an edge (seen); where the map is
// continuous it went through the surface (blocked), as it does when a nearer surface comes
// in front of it later, or when it leaves the frame, where nothing is known. Bit 3·i + l:
// direction i·45°, ring l of three of equal area.
uint pupil_visibility(ivec2 p, float v_hidden) {
    const float RHO[3] = float[3](0.57735027, 0.81649658, 1.0);
    float v_top = frame.dioptre_min + frame.dioptre_step * float(frame.object_count - 1u);
    float k = max(push.parallax_px_per_d, 1e-6);
    float reach = min(RHO[2] * k * max(v_top - v_hidden, 0.0) + 1.0,
                      2.0 * float(frame.max_radius) + 2.0);
    float tolerance = frame.group_tolerance_d;
    float v_start = visible_vergence(p);
    uint mask = 0u;
    for (uint i = 0u; i < 8u; i++) {
        vec2 e = vec2(cos(float(i) * PI / 4.0), sin(float(i) * PI / 4.0));
        uint state[3] = uint[3](0u, 0u, 0u);  // 0 behind, 1 past an edge, 2 blocked
        float previous = v_start;
        for (float s = 1.0; s <= reach; s += 1.0) {
            ivec2 q = ivec2(floor(vec2(p) + 0.5 + s * e));
            if (any(lessThan(q, ivec2(0))) || q.x >= int(frame.width) || q.y >= int(frame.height)) {
                break;
            }
            float v0 = visible_vergence(q);
            bool edge = previous - v0 > tolerance;
            for (uint l = 0u; l < 3u; l++) {
                float v = v_hidden + s / (RHO[l] * k);
                if (state[l] == 0u && v >= v0) {
                    state[l] = edge ? 1u : 2u;
                } else if (state[l] == 1u && v0 > v + tolerance) {
                    state[l] = 2u;
                }
            }
            previous = v0;
            if (state[0] == 2u && state[1] == 2u && state[2] == 2u) {
                break;
            }
        }
        for (uint l = 0u; l < 3u; l++) {
            if (state[l] == 1u) {
                mask |= 1u << (3u * i + l);
            }
        }
    }
    return mask;
}

// Near the frame's border the visible layer's coverage falls short because nothing lies
// beyond the frame, not because its edge lets light by: without the pupil test, a hidden
// fragment there would fill that gap with what no pupil point sees (e.g. geometry under a
// floor). It is kept only farther from the border than the visible surface's blur radius.
bool near_border(uvec2 p, float ray, float last) {
    float d0 = imageLoad(depth_in, ivec2(p)).r;
    bool finite0 = d0 > 0.0 && !isinf(d0) && !isnan(d0);
    float v0 = finite0 ? 1.0 / (d0 * ray) : 0.0;
    float i0f = clamp((v0 - frame.dioptre_min) / frame.dioptre_step, 0.0, last);
    uint j0 = uint(floor(i0f));
    uint j1 = min(j0 + 1u, frame.object_count - 1u);
    float r0 = min(max(mix(radii[j0].y, radii[j1].y, i0f - float(j0)), 0.0), float(frame.max_radius));
    vec2 c = vec2(p) + 0.5;
    float border = min(min(c.x, float(frame.width) - c.x), min(c.y, float(frame.height) - c.y));
    return border < r0 + 1.0;
}

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
        if (push.pupil_visibility != 0u) {
            uint mask = pupil_visibility(ivec2(p), dioptre);
            // Kept as seen from the kernel's side: light through the pupil point u lands at
            // u·(focus − vergence)·f from the point's pixel, so a point nearer than the focus
            // lands on the side opposite its pupil point.
            if (dioptre > push.focus_d) {
                mask = ((mask >> 12u) | (mask << 12u)) & ALL_RAYS;
            }
            // A fragment none of whose rays pass still takes its place in its depth group's
            // coverage (the surface it belongs to continues behind the nearer one), with no
            // light: the group's colour comes from what the pupil sees.
            f.size = 1u | HIDDEN_FRAGMENT | (mask << 8u);
        } else if (near_border(p, ray, last)) {
            f.size = 0u;
        }
    }
    f.dioptre = dioptre;
    store_fragment(g.y * frame.width + g.x, f);
}
