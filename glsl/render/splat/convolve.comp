#version 460
// Convolution: one workgroup per tile walks the tile's sorted list front to back, streaming
// fragments through shared memory in batches, and blends each fragment's kernel into every
// pixel of the tile (src/render/blend.rs): per pixel and channel, consecutive fragments whose
// vergences differ by at most the group tolerance form a group that adds linearly
// (Cg += w·c, Ag += w); groups composite front to back, C += (1 − A)·Cg/max(Ag, 1),
// A += (1 − A)·min(Ag, 1); the output is C / A. A hidden-layer fragment's light counts only
// where its rays pass the nearer surfaces to the pupil (close_group, pupil_share).
// (blend_mode 1: the seed paper's per-fragment C += (1 − A)·w·c, A += (1 − A)·w.) The kernel
// weight w comes from two trilinear lookups in the PSF texture (floor and ceiling radius; the
// layer axis blends the two neighbouring object distances), mixed by frac(radius), at the
// kernel offset of the local pinhole scale; off axis, the kernels of the four field nodes
// around the fragment, mixed bilinearly (glsl/common/field.glsl).
// This walk is for GPUs, where a fragment's uniform branches skip what it does not need; CPU
// implementations run convolve_visits.comp, which computes the same in another shape.
#extension GL_GOOGLE_include_directive : require
// Every constant-count loop is unrolled: lavapipe's shader compiler caps the iterations of all
// loops of one invocation together at 65535 and silently stops the rest, leaving pixels
// unwritten on long tile lists (off axis the four-node and per-pixel loops ran per fragment).
#extension GL_EXT_control_flow_attributes : require
#define FRAME_BINDING 12
#define BANDS_BINDING 7
#define ATLAS_BINDING 8
#define LAYER_ATLAS_BINDING 13
#define LAYER_TEXTURE_BINDING 14
#define LAYER_SUMS_BINDING 15
#include "splat.glsl"
#include "band.glsl"
#include "layer_atlas.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler3D psf_texture;
FRAGMENT_BUFFERS(1, 9, 10, 11, readonly)
FRAGMENT_LOAD
layout(std430, binding = 2) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 3) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = 4) readonly buffer Entries { uvec2 entries[]; };
layout(binding = 5, rgba32f) writeonly uniform image2D color_out;
layout(std430, binding = 6) readonly buffer Field { vec4 field_header[2]; vec4 node_radii[]; };
#include "field.glsl"
#include "atlas.glsl"

// The tile side is fixed per pipeline, so the per-thread pixel arrays have a compile-time
// size and live in registers (dynamic sizes cost CPU implementations such as lavapipe dearly).
layout(constant_id = 0) const uint TILE = 8u;
// Off axis (a field lattice of more than one node): a pipeline of its own, so that the on-axis
// convolution carries none of the four-node code.
layout(constant_id = 1) const uint OFF_AXIS = 0u;
// 1: each object distance's own kernel from the layer texture, one read for all channels
// (frame.layered says the same; a pipeline of its own, so each carries only its reads).
layout(constant_id = 3) const uint LAYERED = 0u;
// 0: the frame has no hidden layers (pupil_share is 1): a pipeline of its own, like the
// visits walk's.
layout(constant_id = 4) const uint HIDDEN = 1u;
const uint PER_AXIS = TILE / 8u;
const uint PIXELS = PER_AXIS * PER_AXIS;
// The batch is split so that the reach test, which rejects most (pixel, fragment) pairs,
// reads 16 bytes instead of the whole 48-byte fragment.
shared vec4 batch_reach[64];   // centre.xy, the footprint's half-extents on the screen
shared vec4 batch_scale[64];   // the local scale's map J (J₁₁, J₁₂, J₂₂), the footprint's bound
shared Fragment batch[64];
shared uvec4 batch_nodes[64];  // off axis: the four field nodes around the fragment
shared vec4 batch_node_weights[64];
shared uint unsaturated;       // threads with a pixel whose closed groups cover < 1 − ε

// RGB kernel values at radius level l (divided by the (2r+1)² storage scale of its block) of
// field node `node`, at offset d from the kernel's centre; a merged block of 4×4 pixels and up
// reads the level's kernel summed over its side (kernel_slot). Past the slot's zero ring, and
// past the largest level, the kernel is zero and the atlas holds other slots or nothing:
// nothing is read there.
vec3 kernel_rgb(vec2 d, float l, float index, uint node, uint size) {
    uint level = uint(l);
    if (level >= level_count()) {
        return vec3(0.0);
    }
    uint slot = kernel_slot(level, size);
    if (any(greaterThanEqual(abs(d), vec2(slot_bound(slot, level))))) {
        return vec3(0.0);
    }
    uint r = level_block_radius(level);
    vec3 extent = vec3(textureSize(psf_texture, 0));
    vec3 uvw = vec3((vec2(node_origin(node)) + slot_point(slot) + d) / extent.xy,
                    (index + 0.5) / extent.z);
    float k = float(2u * r + 1u);
    return textureLod(psf_texture, uvw, 0.0).rgb / (k * k);
}

// Per-channel kernel of fragment f at offset d at field node `node`: each channel's radius
// lies between two radius levels; when all channels' levels fall within three consecutive ones
// (the usual case), the three lookups serve every channel, else each channel takes its own two.
vec3 kernel_at(Fragment f, vec2 d, uint node) {
    uint size = block_size(f);
    if (LAYERED != 0u) {
        return layer_read(layer_kind(size), d, vec2(layer_node_origin(node)),
                          (f.index + 0.5) / float(textureSize(layer_texture, 0).z));
    }
    vec3 level = level_of_radius(f.radius);
    vec3 lo = floor(level);
    vec3 t = level - lo;
    float base = min(lo.r, min(lo.g, lo.b));
    float top = max(ceil(level.r), max(ceil(level.g), ceil(level.b)));
    vec3 w;
    if (top - base <= 2.0) {
        vec3 s0 = kernel_rgb(d, base, f.index, node, size);
        vec3 s1 = top > base ? kernel_rgb(d, base + 1.0, f.index, node, size) : s0;
        vec3 s2 = top > base + 1.0 ? kernel_rgb(d, base + 2.0, f.index, node, size) : s1;
        // Component-wise selection (no dynamic indexing): channel c reads s[i0] and s[i0 + 1].
        vec3 i0 = lo - base;
        vec3 a = mix(mix(s0, s1, step(0.5, i0)), s2, step(1.5, i0));
        vec3 b = mix(s1, s2, step(0.5, i0));
        w = mix(a, b, t);
    } else {
        [[unroll]] for (int c = 0; c < 3; c++) {
            float a = kernel_rgb(d, lo[c], f.index, node, size)[c];
            w[c] = t[c] > 0.0 ? mix(a, kernel_rgb(d, lo[c] + 1.0, f.index, node, size)[c], t[c]) : a;
        }
    }
    return w;
}

// Per-channel weight of batch fragment j at offset d: off axis, the four field nodes' kernels
// at the fragment's radius, mixed bilinearly in field angle.
vec3 fragment_weight(uint j, Fragment f, vec2 d) {
    vec3 w;
    if (OFF_AXIS == 0u) {
        w = kernel_at(f, d, 0u);
    } else {
        w = vec3(0.0);
        uvec4 nodes = batch_nodes[j];
        vec4 weights = batch_node_weights[j];
        [[unroll]] for (uint k = 0u; k < 4u; k++) {
            if (weights[k] > 0.0) {
                w += weights[k] * kernel_at(f, d, nodes[k]);
            }
        }
    }
    uint size = block_size(f);
    if (size > 1u) {
        // A merged block carries size² pixels' worth of the same light.
        float n = float(size * size);
        w = frame.blend_mode == 0u ? n * w
                                   : vec3(1.0) - pow(max(vec3(1.0) - w, vec3(0.0)), vec3(n));
    }
    return w;
}

// Layered, a merged block in the wide field (block_reads in splat.glsl): its pixels'
// kernels summed where they lie in kernel space, at kernel offset k of its centre; m: the
// local scale's map J.
vec3 wide_block_weight(Fragment f, vec2 k, vec3 m) {
    uint size = block_size(f);
    float layer = (f.index + 0.5) / float(textureSize(layer_texture, 0).z);
    if (size == 2u) {
        // the four pixels at ±½ from the centre: offsets ±a = ±J·(½, ½), ±b = ±J·(½, −½)
        vec2 a = 0.5 * vec2(m.x + m.y, m.y + m.z);
        vec2 b = 0.5 * vec2(m.x - m.y, m.y - m.z);
        return layer_read(0u, k - a, vec2(0.0), layer) + layer_read(0u, k + a, vec2(0.0), layer)
             + layer_read(0u, k - b, vec2(0.0), layer) + layer_read(0u, k + b, vec2(0.0), layer);
    }
    return float(size * size) * layer_box(k, 0.5 * float(size) * m.xz, layer);
}

#include "blend.glsl"

void main() {
    load_band();
    uint tile = band.first_tile + gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
    if (tile >= band.end_tile) {
        return;
    }
    uint tx = tile % frame.tiles_x;
    uint ty = tile / frame.tiles_x;
    uint n = counts[tile];
    if (!list_fits(offsets[tile], n)) {
        return;
    }
    uint base = offsets[tile] - band.first_entry;
    uint local_index = gl_LocalInvocationIndex;

    vec2 centre[PIXELS];
    vec3 C[PIXELS];
    vec3 A[PIXELS];
    vec3 Cg[PIXELS];     // the open group's light and coverage
    vec3 Ag[PIXELS];
    vec3 Gg[PIXELS];     // the open group's weight of light that reaches the pupil
    float last[PIXELS];  // vergence of the last fragment that reached the pixel (−1: none)
    [[unroll]] for (uint q = 0u; q < PIXELS; q++) {
        uvec2 pixel = uvec2(tx, ty) * TILE + gl_LocalInvocationID.xy + 8u * uvec2(q % PER_AXIS, q / PER_AXIS);
        centre[q] = vec2(pixel) + 0.5;
        C[q] = vec3(0.0);
        A[q] = vec3(0.0);
        Cg[q] = vec3(0.0);
        Ag[q] = vec3(0.0);
        Gg[q] = vec3(0.0);
        last[q] = -1.0;
    }
    bool grouped = frame.blend_mode == 0u;

    for (uint start = 0u; start < n; start += 64u) {
        if (local_index == 0u) {
            unsaturated = 0u;
        }
        if (start + local_index < n) {
            Fragment f = load_fragment(entries[base + start + local_index].y);
            batch[local_index] = f;
            if (OFF_AXIS != 0u) {
                uvec4 nodes;
                vec4 weights;
                field_corners(f.center, nodes, weights);
                batch_nodes[local_index] = nodes;
                batch_node_weights[local_index] = weights;
            }
            Footprint fp = fragment_footprint(f);
            batch_reach[local_index] = vec4(f.center, footprint_extent(fp));
            batch_scale[local_index] = vec4(fp.map, fp.bound);
        }
        barrier();
        uint batch_size = min(64u, n - start);
        for (uint j = 0u; j < batch_size; j++) {
            vec4 g = batch_reach[j];
            [[unroll]] for (uint q = 0u; q < PIXELS; q++) {
                vec2 d = centre[q] - g.xy;
                // The reach test: the footprint's bounding box on the screen, which rejects
                // most pairs with one load, then the footprint itself in kernel space (off the
                // centre a parallelogram on the screen).
                if (abs(d.x) >= g.z || abs(d.y) >= g.w) {
                    continue;
                }
                vec4 m = batch_scale[j];
                vec2 k = map_offset(m.xyz, d);
                if (abs(k.x) >= m.w || abs(k.y) >= m.w) {
                    continue;
                }
                Fragment f = batch[j];
                vec3 w;
                // J's diagonal falls below 1 where the local scale applies
                if (m.x < 1.0 || m.z < 1.0) {
                    w = LAYERED != 0u && block_size(f) > 1u && block_reads()
                        ? wide_block_weight(f, k, m.xyz) : fragment_weight(j, f, k);
                    // the map's determinant: the kernel's weight per screen pixel
                    w *= map_area(m.xyz);
                } else {
                    w = fragment_weight(j, f, d);
                }
                vec3 g = HIDDEN == 0u ? vec3(1.0)
                                      : pupil_share(f.size, f.radius, pupil_inner(f.size), d);
                if (grouped) {
                    if (last[q] >= 0.0 && abs(f.dioptre - last[q]) > frame.group_tolerance_d) {
                        close_group(C[q], A[q], Cg[q], Ag[q], Gg[q]);
                    }
                    Cg[q] += (w * g) * f.color;
                    Ag[q] += w;
                    Gg[q] += w * g;
                    last[q] = f.dioptre;
                } else {
                    C[q] += (vec3(1.0) - A[q]) * (w * g) * f.color;
                    A[q] += (vec3(1.0) - A[q]) * (w * g);
                }
            }
        }
        // Early exit: once every pixel of the tile is covered to 1 − ε in every channel by
        // closed groups (or by the per-fragment blend), what lies behind adds at most ε of its
        // light; the open group is not closed yet and may still grow, so it does not count.
        bool saturated = true;
        [[unroll]] for (uint q = 0u; q < PIXELS; q++) {
            saturated = saturated && all(greaterThanEqual(A[q], vec3(1.0 - frame.saturation_epsilon)));
        }
        if (!saturated || frame.saturation_epsilon <= 0.0) {
            atomicAdd(unsaturated, 1u);
        }
        barrier();
        bool done = unsaturated == 0u;
        barrier();
        if (done) {
            break;
        }
    }

    [[unroll]] for (uint q = 0u; q < PIXELS; q++) {
        close_group(C[q], A[q], Cg[q], Ag[q], Gg[q]);
        uvec2 pixel = uvec2(centre[q]);
        if (pixel.x < frame.width && pixel.y < frame.height) {
            vec3 behind;
            if (any(lessThan(A[q], vec3(1.0))) && background_behind(pixel, behind)) {
                C[q] += max(vec3(1.0) - A[q], vec3(0.0)) * behind;
                A[q] = max(A[q], vec3(1.0));
            }
            vec3 a = A[q];
            vec3 color = vec3(a.r > 0.0 ? C[q].r / a.r : 0.0,
                              a.g > 0.0 ? C[q].g / a.g : 0.0,
                              a.b > 0.0 ? C[q].b / a.b : 0.0);
            imageStore(color_out, ivec2(pixel), vec4(color, 1.0));
        }
    }
}
