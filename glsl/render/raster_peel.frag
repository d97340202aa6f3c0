#version 460
// Depth peeling: the raster pass again, keeping only what lies behind the previous layer.
// A fragment survives when its vergence is smaller than the previous layer's at this pixel
// by more than the gap (frame.ambient.w, dioptres: the blend's depth-group tolerance, so a
// layer never repeats the surface in front of it), and when its surface faces the eye (the
// back of an opaque object is never seen, from any point of the pupil; raster_shade.glsl's
// seen_from_behind decides).
#extension GL_GOOGLE_include_directive : require

#include "raster_frame.glsl"

layout(binding = 2) uniform sampler2D previous_depth;

#include "raster_shade.glsl"

void main() {
    vec3 facet = facet_toward_eye();
    float previous = texelFetch(previous_depth, ivec2(gl_FragCoord.xy), 0).r;
    float gap_d = frame.ambient.w;
    if (!(previous > 0.0) || isinf(previous) || 1.0 / fragment_view_depth() > 1.0 / previous - gap_d) {
        discard;
    }
    // A hidden layer keeps surfaces whose own normal faces the eye: it drops the far side of
    // an object and also the last facets before a smooth object's silhouette, whose normals
    // already turn away (the winding test of seen_from_behind would keep those, a few mm
    // behind the rim the first layer holds, in place of the surface behind the rim).
    if (dot(world_normal, frame.camera_position.xyz - world_position) < 0.0) {
        discard;
    }
    shade_fragment(facet);
}
