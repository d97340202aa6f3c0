// Per-frame data shared by raster.vert and raster.frag (std140; mirrors FrameUniform in
// src/render/raster.rs).

#define MAX_LIGHTS 16

struct Light {
    // xyz: direction the light travels (w = 0) or position in metres (w = 1).
    vec4 position;
    // Directional: illuminance in lux per channel. Point: intensity in cd per channel.
    vec4 rgb;
};

layout(std140, binding = 0) uniform Frame {
    mat4 view_proj;
    mat4 view;
    vec4 camera_position;
    // Ambient illuminance (lux per channel).
    vec4 ambient;
    // x: number of lights in use.
    uvec4 counts;
    Light lights[MAX_LIGHTS];
} frame;
