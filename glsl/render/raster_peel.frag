#version 460
// Depth peeling: the raster pass again, keeping only what lies behind the previous layer,
// sample by sample. A covered sample survives when the fragment's vergence is smaller than
// the previous layer's at that sample by more than the gap (frame.ambient.w, dioptres: the
// blend's depth-group tolerance, so a layer never repeats the surface in front of it). Peeling
// per pixel, behind the pixel's nearest sample, let a smooth object's own rim facets (a few
// mm behind that sample, at other samples of the same pixel) into the hidden layer in place
// of the surface behind the rim (docs/validation.md, "Silhouettes"). A surface must also face
// the eye (the back of an opaque object is never seen, from any point of the pupil).
#extension GL_GOOGLE_include_directive : require

#include "raster_frame.glsl"

// The previous layer's view depth per sample (the far plane where it shows nothing, which
// hides nothing behind it).
layout(binding = 2) uniform sampler2DMS previous_samples;

#include "raster_shade.glsl"

void main() {
    vec3 facet = facet_toward_eye();
    float d = fragment_view_depth();
    float gap_d = frame.ambient.w;
    int kept = 0;
    for (int s = 0; s < 4; ++s) {
        if ((gl_SampleMaskIn[0] & (1 << s)) == 0) {
            continue;
        }
        float previous = texelFetch(previous_samples, ivec2(gl_FragCoord.xy), s).r;
        if (previous > 0.0 && 1.0 / d < 1.0 / previous - gap_d) {
            kept |= 1 << s;
        }
    }
    // A hidden layer keeps surfaces whose own normal faces the eye: it drops the far side of
    // an object and also the last facets before a smooth object's silhouette, whose normals
    // already turn away (the winding test of seen_from_behind would keep those).
    if (kept == 0 || dot(world_normal, frame.camera_position.xyz - world_position) < 0.0) {
        discard;
    }
    gl_SampleMask[0] = kept;
    shade_fragment(facet);
}
