#version 460
// raster.frag as it shaded silhouettes before the fix: inputs interpolated at the pixel centre
// (no `centroid`), the two-sided flip judged by the view and depths bounded by the object's box
// alone (raster_shade.glsl). Built only so
// that tests/it/silhouettes.rs can show its negative control failing; never used to render.

#define PRE_SILHOUETTE_FIX

#include "raster_frame.glsl"

#include "raster_shade.glsl"

void main() {
    shade_fragment(facet_toward_eye());
}
