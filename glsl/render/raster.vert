#version 460
// Scene geometry arrives in world space (placed once on the CPU); only the camera changes
// per frame.

#include "raster_frame.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec2 uv;
layout(location = 3) out float view_depth;

void main() {
    vec4 p = vec4(in_position, 1.0);
    gl_Position = frame.view_proj * p;
    world_position = in_position;
    world_normal = in_normal;
    uv = in_uv;
    // Distance along the view direction: view space looks down -z. Interpolated
    // perspective-correctly, it is exact on every planar triangle.
    view_depth = -(frame.view * p).z;
}
