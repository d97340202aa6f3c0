// Shading shared by raster.frag and raster_peel.frag (see raster.frag).

layout(binding = 1) uniform sampler2D albedo_map;

layout(push_constant) uniform Material {
    // rgb: reflectance; a > 0.5: multiply by albedo_map.
    vec4 albedo;
    // rgb: emitted luminance (cd/m² in Y).
    vec4 emission;
    // x, y: nearest and farthest view depth (m) of this draw's bounding box, within the clip
    // range.
    vec4 depth_range_m;
} material;

// Where a pixel's surface inputs are evaluated. With 4× MSAA this shader runs once per pixel
// and its result goes to every sample the triangle covers; a plain input is interpolated at the
// pixel's centre even where the centre lies outside the triangle, i.e. extrapolated past a
// silhouette: position and depth run off the surface and the normal turns on past the rim
// (docs/validation.md, "Silhouettes"). `centroid` evaluates them inside the covered samples,
// so an edge pixel mixes colours and a depth that its surfaces really have.
// raster_centre.frag defines PRE_SILHOUETTE_FIX: the old interpolation, the old two-sided rule
// and the old depth bound (below), kept only as the negative control of
// tests/it/silhouettes.rs.
#ifdef PRE_SILHOUETTE_FIX
#define SURFACE_INPUT in
#else
#define SURFACE_INPUT centroid in
#endif

layout(location = 0) SURFACE_INPUT vec3 world_position;
layout(location = 1) SURFACE_INPUT vec3 world_normal;
layout(location = 2) SURFACE_INPUT vec2 uv;
layout(location = 3) SURFACE_INPUT float view_depth;
layout(location = 4) flat in float vertex_view_depth;
layout(location = 5) flat in float vertex_reach_m;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;

const float PI = 3.14159265358979;

// The fragment's view depth, kept within what its triangle can have: within the reach of the
// triangle's first vertex (no point of a triangle lies farther from a vertex than that
// vertex's longest edge, src/scene/mesh.rs) and within its object's box. A triangle seen
// edge-on (a facet on a silhouette) covers samples while its screen area is nearly zero; the
// interpolation set up from that area is then ill-conditioned, and a rasteriser returns depths
// off the surface even at covered samples, centroid or not: lavapipe gave 1.7 mm for a column
// 3.5 m away in the walk scene at 64×36, and 0.183 m on the rim of the default frame's red
// sphere, whose rim lies at 0.19–0.20 m. That pixel formed a depth group of its own in front
// of the sphere, and its coverage drew the eye's PSF around it: a star. The bounds are
// inactive on every well-conditioned fragment.
float fragment_view_depth() {
#ifdef PRE_SILHOUETTE_FIX
    return clamp(view_depth, material.depth_range_m.x, material.depth_range_m.y);
#else
    float d = view_depth;
    if (abs(d - vertex_view_depth) > vertex_reach_m) {
        // provably off the triangle: take the depth of its first vertex, which it has
        d = vertex_view_depth;
    }
    return clamp(d, material.depth_range_m.x, material.depth_range_m.y);
#endif
}

// The facet's own normal, turned toward the eye (zero where the facet is seen edge-on), for a
// vertex normal that is missing. Call it before any discard: derivatives need the whole quad.
vec3 facet_toward_eye() {
    vec3 facet = cross(dFdx(world_position), dFdy(world_position));
    return dot(facet, frame.camera_position.xyz - world_position) < 0.0 ? -facet : facet;
}

// Whether the eye sees the side of the surface its normal points away from (the back of an
// object, or the far side of a two-sided sheet). The rasteriser's winding test decides: the
// scene stores every triangle wound to agree with its normals (src/scene/mesh.rs), and
// gl_FrontFacing is exact even on a facet seen edge-on. Judging by the view instead (the old
// rule) flips a smooth surface's rim, whose interpolated normals legitimately turn past 90°
// from the view before its polygonal silhouette, and lights a shadowed rim from the wrong
// side; the facet's normal from screen derivatives is no better there, since centroid inputs
// make those derivatives unreliable on the last pixels of a silhouette.
bool seen_from_behind(vec3 n) {
#ifdef PRE_SILHOUETTE_FIX
    return dot(n, frame.camera_position.xyz - world_position) < 0.0;
#else
    return !gl_FrontFacing;
#endif
}

// `facet`: facet_toward_eye(), taken where the whole quad was still running.
void shade_fragment(vec3 facet) {
    vec3 n = world_normal;
    float len = length(n);
    if (len > 1e-20) {
        n /= len;
    } else {
        // Degenerate normal: fall back to the facet's own.
        n = normalize(facet);
    }
    // Surfaces are two-sided: the side seen is lit.
    if (seen_from_behind(n)) {
        n = -n;
    }
    vec3 albedo = material.albedo.rgb;
    if (material.albedo.a > 0.5) {
        albedo *= texture(albedo_map, uv).rgb;
    }
    vec3 illuminance = frame.ambient.rgb;
    for (uint i = 0; i < frame.counts.x; ++i) {
        Light light = frame.lights[i];
        if (light.position.w == 0.0) {
            illuminance += light.rgb.rgb * max(dot(n, -light.position.xyz), 0.0);
        } else {
            vec3 d = light.position.xyz - world_position;
            float r2 = max(dot(d, d), 1e-12);
            illuminance += light.rgb.rgb * max(dot(n, d * inversesqrt(r2)), 0.0) / r2;
        }
    }
    out_color = vec4(albedo * illuminance / PI + material.emission.rgb, 1.0);
    out_depth = fragment_view_depth();
}
