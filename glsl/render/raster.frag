#version 460
// Lambertian shading calibrated in photometric units: luminance = reflectance · E / π, with
// E the illuminance in lux, plus emitted luminance in cd/m². Surfaces are two-sided because
// OBJ windings are unreliable.

#include "raster_frame.glsl"

#include "raster_shade.glsl"

void main() {
    shade_fragment(facet_toward_eye());
}
