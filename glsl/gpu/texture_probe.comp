#version 460
// Samples a 3D texture with the hardware's trilinear filter at arbitrary texel-space points.
// Used to check filtering against a CPU reference, and by later passes' tests to inspect the
// PSF texture exactly as the convolution pass will see it.

layout(local_size_x = 64) in;

layout(binding = 0) uniform sampler3D volume;
layout(std430, binding = 1) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 2) writeonly buffer Samples { vec4 samples[]; };

layout(push_constant) uniform Push {
    uint count;
} push;

void main() {
    vec3 size = vec3(textureSize(volume, 0));
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    for (uint i = gl_GlobalInvocationID.x; i < push.count; i += stride) {
        // Texel-space point: texel centres sit at integer + 0.5.
        samples[i] = textureLod(volume, points[i].xyz / size, 0.0);
    }
}
