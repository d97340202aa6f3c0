// Shading shared by raster.frag and raster_peel.frag (see raster.frag).

layout(binding = 1) uniform sampler2D albedo_map;

layout(push_constant) uniform Material {
    // rgb: reflectance; a > 0.5: multiply by albedo_map.
    vec4 albedo;
    // rgb: emitted luminance (cd/m² in Y).
    vec4 emission;
} material;

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in float view_depth;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;

const float PI = 3.14159265358979;

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
    out_depth = view_depth;
}
