#version 460
// Takes a frame the rasteriser left on the GPU into splat's inputs: colour as it is, and depth
// nearer than the nearest supported distance clamped to it, as host inputs are clamped.

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) readonly uniform image2D raster_color;
layout(std430, binding = 1) readonly buffer RasterDepth { float raster_depth_m[]; };
layout(binding = 2, rgba32f) writeonly uniform image2D color_in;
layout(binding = 3, r32f) writeonly uniform image2D depth_in;

layout(push_constant) uniform Push {
    uint width;
    uint height;
    float near_m;
} push;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= push.width || p.y >= push.height) {
        return;
    }
    float d = raster_depth_m[p.y * push.width + p.x];
    if (d > 0.0 && d < push.near_m) {
        d = push.near_m;
    }
    imageStore(color_in, ivec2(p), imageLoad(raster_color, ivec2(p)));
    imageStore(depth_in, ivec2(p), vec4(d, 0.0, 0.0, 0.0));
}
