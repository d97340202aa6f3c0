#version 460
// Scene geometry arrives in world space (placed once on the CPU); only the camera changes
// per frame.

#include "raster_frame.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in float in_reach_m;

layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec2 uv;
layout(location = 3) out float view_depth;
// The provoking (first) vertex's view depth and reach: a fragment's depth lies within the
// reach of its triangle's first vertex (raster_shade.glsl).
layout(location = 4) flat out float vertex_view_depth;
layout(location = 5) flat out float vertex_reach_m;

void main() {
    vec4 p = vec4(in_position, 1.0);
    gl_Position = frame.view_proj * p;
    world_position = in_position;
    world_normal = in_normal;
    uv = in_uv;
    // Distance along the view direction: view space looks down -z. Interpolated
    // perspective-correctly, it is exact on every planar triangle.
    view_depth = -(frame.view * p).z;
    vertex_view_depth = view_depth;
    vertex_reach_m = in_reach_m;
}
