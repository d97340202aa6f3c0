#version 460
// Takes one depth layer the rasteriser left on the GPU into splat's inputs, rows
// [layer·height, (layer+1)·height) (layers stack downwards), doing on the GPU what the host
// does to peeled layers it reads back (Rasterizer::render_layers): in a hidden layer, a pixel
// with coverage keeps its surface's own colour (coverage divided out) and an empty one gets
// colour 0 and depth +∞. Depth nearer than the nearest supported distance is clamped to it,
// as host inputs are clamped. The next layer's peel reads this layer's samples from the
// rasteriser's own targets, so depth never visits the host.

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) readonly uniform image2D raster_color;
layout(std430, binding = 1) readonly buffer RasterDepth { float raster_depth_m[]; };
layout(binding = 2, rgba32f) writeonly uniform image2D color_in;
layout(binding = 3, r32f) writeonly uniform image2D depth_in;

layout(push_constant) uniform Push {
    uint width;
    uint height;
    uint layer;
    float near_m;
    float far_m;
} push;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= push.width || p.y >= push.height) {
        return;
    }
    const float INF = uintBitsToFloat(0x7f800000u);
    float d = raster_depth_m[p.y * push.width + p.x];
    vec4 c = imageLoad(raster_color, ivec2(p));
    if (push.layer > 0u) {
        if (c.a > 1e-6 && d < push.far_m) {
            c = vec4(c.rgb / c.a, 1.0);
        } else {
            c = vec4(0.0);
            d = INF;
        }
    }
    if (d > 0.0 && d < push.near_m) {
        d = push.near_m;
    }
    ivec2 q = ivec2(p.x, p.y + push.layer * push.height);
    imageStore(color_in, q, c);
    imageStore(depth_in, q, vec4(d, 0.0, 0.0, 0.0));
}
