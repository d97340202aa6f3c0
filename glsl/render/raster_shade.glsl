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

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in float view_depth;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;

const float PI = 3.14159265358979;

// The fragment's view depth, kept within its object's box. A triangle seen edge-on (a facet on
// a cylinder's silhouette) covers samples while its screen area is nearly zero; the
// interpolation set up from that area is then meaningless, and a rasteriser returns any depth
// for those samples (lavapipe gave 1.7 mm for a column 3.5 m away in the walk scene at 64×36,
// which the nearest-sample resolve then kept). Whatever the driver does, a surface's depth
// lies inside the box around its vertices; the clamp is inactive on every well-conditioned
// fragment.
float fragment_view_depth() {
    return clamp(view_depth, material.depth_range_m.x, material.depth_range_m.y);
}

void shade_fragment() {
    vec3 n = world_normal;
    float len = length(n);
    if (len > 1e-20) {
        n /= len;
    } else {
        // Degenerate normal: fall back to the facet's own.
        n = normalize(cross(dFdx(world_position), dFdy(world_position)));
    }
    vec3 to_eye = frame.camera_position.xyz - world_position;
    if (dot(n, to_eye) < 0.0) {
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
