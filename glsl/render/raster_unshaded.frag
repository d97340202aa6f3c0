#version 460
// The raster pass with no shading: the material's reflectance, unlit, and the depth
// interpolated inside the covered samples. Only `ocular bench --draw-unshaded` uses it, to time
// the draw's fixed-function share (rasterisation, multisampled writes, resolve) apart from its
// fragment work. The texture and frame reads below keep the bindings of raster.frag, so both
// pipelines bind the same resources; they add nothing measurable.

#include "raster_frame.glsl"

#include "raster_shade.glsl"

void main() {
    out_color = material.albedo + textureLod(albedo_map, vec2(0.5), 0.0) * 1e-30
        + frame.ambient * 1e-30;
    out_depth = view_depth;
}
