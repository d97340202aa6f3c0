#version 460
// Convolution for CPU implementations (lavapipe): the same result as convolve.comp (which says
// what the pass computes), walked in the shape a CPU runs fast. Such an implementation runs
// both sides of every branch and a loop's body at least once, so convolve.comp's per-pixel
// branches (both local-scale sides, both channel-span cases: up to eighteen texture reads per
// (pixel, fragment) pair) all execute. Here each batch entry's reads are planned once in shared
// memory and each subgroup loops only over the slots that reach its pixels; a visit is the reach
// test, three filtered reads and the blend. On a GPU this shape is slower (its shared memory
// halves the occupancy; on an H200 the convolution took 1.6× convolve.comp's time), so the
// pass picks the shader by the device's kind (src/render/splat/convolve.rs).
#extension GL_GOOGLE_include_directive : require
// Every constant-count loop is unrolled: lavapipe's shader compiler caps the iterations of all
// loops of one invocation together at 65535 and silently stops the rest, leaving pixels
// unwritten on long tile lists (off axis the four-node and per-pixel loops ran per fragment).
#extension GL_EXT_control_flow_attributes : require
#extension GL_KHR_shader_subgroup_arithmetic : require
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
// The seed paper's per-fragment blend (1) or depth groups (0); frame.blend_mode says the same.
layout(constant_id = 2) const uint PER_FRAGMENT_BLEND = 0u;
// 1: each object distance's own kernel from the layer texture: one read per visit, all
// channels (a pipeline of its own: a CPU implementation pays for every read it contains).
layout(constant_id = 3) const uint LAYERED = 0u;
// 0: the frame has no hidden layers, so no fragment's light is partly blocked (pupil_share is
// 1): a pipeline of its own, since a CPU implementation pays for pupil_share on every visit.
layout(constant_id = 4) const uint HIDDEN = 1u;
const uint PER_AXIS = TILE / 8u;
const uint PIXELS = PER_AXIS * PER_AXIS;
const bool grouped = PER_FRAGMENT_BLEND == 0u;

// Per pixel of this thread: its centre, the composited light and coverage, the open group's
// light, coverage and weight of light that reaches the pupil, and the vergence of the last
// fragment that reached it (−1: none).
vec2 centre[PIXELS];
vec3 C[PIXELS];
vec3 A[PIXELS];
vec3 Cg[PIXELS];
vec3 Ag[PIXELS];
vec3 Gg[PIXELS];
float last[PIXELS];
// A batch of up to 64 list entries is prepared once in shared memory (one thread each), so
// that what a pixel does per visit is only the reach test, three filtered reads and the blend.
// What a fragment needs from the PSF texture is decided then: each channel mixes the two
// radius levels around its radius, and the reads are grouped by channel into slots of at most
// three levels each, with per-channel coefficients (the radius mix, the block's (2r+1)² storage
// scale, and in the grouped blend the local scale's weight and a merged block's pixel count).
// The usual fragment is one slot; one whose channels span more levels takes two or three
// consecutive slots, each carrying only its own channels' light (zero in the others), so the
// blend sees the same sums in either blend mode. CPU implementations such as lavapipe run both
// sides of every branch and a loop's body at least once, so extra work is paid only as slots.
const uint SLOTS = 96u;
// Filtered reads per slot (two a slot measured 1.4× slower on lavapipe: most fragments' channels
// span three radius levels).
const uint READS = 3u;
shared vec4 slot_reach[SLOTS];     // centre.xy, the footprint's bound, the texture layer coordinate
shared vec4 slot_scale[SLOTS];     // the local scale's map J (J₁₁, J₁₂, J₂₂; I: none), the read's
                                   // code (read_code)
shared vec4 slot_color[SLOTS];     // linear RGB, vergence (D)
shared vec4 slot_read[SLOTS * READS]; // per read: its kernel's offset 0 (slot_point), bound, red coefficient
shared vec4 slot_gb[SLOTS * 2u];   // green and blue coefficients of the three reads, then the
                                   // weight applied after the reads and the per-fragment blend's
                                   // block pixel count (1 otherwise)
shared uvec4 slot_hidden[SLOTS];   // size bits, radius (float bits) per channel
shared vec4 slot_nodes[SLOTS * 2u]; // off axis: the four field nodes' region origins
shared vec4 slot_node_weights[SLOTS];
shared uint entry_slots[64];       // slots per entry of the batch, then their running sum
shared uvec3 patch_slots[8];       // per patch: the batch's slots that reach its pixels
shared uint batch_taken;           // entries of this batch that fit in the slots
shared uint unsaturated;           // threads with a pixel whose closed groups cover < 1 − ε

// A fragment's reads: per slot up to three radius levels and their per-channel coefficients.
struct ReadPlan {
    float levels[9];  // slot s, read i at 3s + i
    vec3 coefs[9];
    uint counts[3];
    uint slots;
};

// Adds level l with coefficient a for channel c to slot s (or to its read of that level).
void plan_add(inout ReadPlan plan, uint s, float l, int c, float a) {
    uint r = level_block_radius(uint(l));
    float k = float(2u * r + 1u);
    bool found = false;
    [[unroll]] for (uint i = 0u; i < 3u; i++) {
        if (!found && i < plan.counts[s] && plan.levels[3u * s + i] == l) {
            plan.coefs[3u * s + i][c] += a / (k * k);
            found = true;
        }
    }
    if (!found) {
        uint i = 3u * s + plan.counts[s];
        plan.levels[i] = l;
        plan.coefs[i] = vec3(0.0);
        plan.coefs[i][c] = a / (k * k);
        plan.counts[s]++;
    }
}

// Levels of slot s not yet among its reads, of the pair (l0, l1) (l1 < 0: none).
uint plan_new_levels(ReadPlan plan, uint s, float l0, float l1) {
    bool has0 = false;
    bool has1 = l1 < 0.0;
    [[unroll]] for (uint i = 0u; i < 3u; i++) {
        bool used = i < plan.counts[s];
        has0 = has0 || (used && plan.levels[3u * s + i] == l0);
        has1 = has1 || (used && plan.levels[3u * s + i] == l1);
    }
    return (has0 ? 0u : 1u) + (has1 ? 0u : 1u);
}

ReadPlan plan_reads(Fragment f, float pre) {
    ReadPlan plan;
    [[unroll]] for (uint i = 0u; i < 9u; i++) {
        plan.levels[i] = 0.0;
        plan.coefs[i] = vec3(0.0);
    }
    plan.counts = uint[3](0u, 0u, 0u);
    if (LAYERED != 0u) {
        // One read of the distance's own kernel (fill_slot places it).
        plan.coefs[0] = vec3(pre / layer_scale());
        plan.counts[0] = 1u;
        plan.slots = 1u;
        return plan;
    }
    vec3 level = level_of_radius(f.radius);
    vec3 lo = floor(level);
    vec3 t = level - lo;
    [[unroll]] for (int c = 0; c < 3; c++) {
        // Past the largest level the kernel is zero: no read there.
        float hi = t[c] > 0.0 && uint(lo[c]) + 1u < level_count() ? lo[c] + 1.0 : -1.0;
        uint s = plan_new_levels(plan, 0u, lo[c], hi) + plan.counts[0] <= READS ? 0u
               : plan_new_levels(plan, 1u, lo[c], hi) + plan.counts[1] <= READS ? 1u : 2u;
        plan_add(plan, s, lo[c], c, (1.0 - t[c]) * pre);
        if (hi >= 0.0) {
            plan_add(plan, s, hi, c, t[c] * pre);
        }
    }
    plan.slots = plan.counts[2] > 0u ? 3u : plan.counts[1] > 0u ? 2u : 1u;
    return plan;
}

// Fills slot j with slot s of fragment f's plan; map is the local scale's map J, code the
// read's (read_code).
void fill_slot(uint j, Fragment f, ReadPlan plan, uint s, vec4 reach, vec3 map, float post,
               float pixels, float code) {
    slot_reach[j] = reach;
    slot_scale[j] = vec4(map, code);
    slot_color[j] = vec4(f.color, f.dioptre);
    slot_hidden[j] = uvec4(f.size, floatBitsToUint(f.radius));
    vec3 coef[3] = vec3[3](vec3(0.0), vec3(0.0), vec3(0.0));
    [[unroll]] for (uint i = 0u; i < READS; i++) {
        bool used = i < plan.counts[s];
        uint l = used ? uint(plan.levels[3u * s + i]) : 0u;
        coef[i] = used ? plan.coefs[3u * s + i] : vec3(0.0);
        if (LAYERED == 0u) {
            // A merged block of 4×4 and up reads its side's block-summed kernel (kernel_slot).
            uint at = kernel_slot(l, block_size(f));
            // An unused read stays harmless: its bound rejects every offset.
            slot_read[READS * j + i] =
                vec4(slot_point(at), used ? slot_bound(at, l) : 0.0, coef[i].r);
        }
    }
    slot_gb[2u * j] = vec4(coef[0].gb, coef[1].gb);
    slot_gb[2u * j + 1u] = vec4(coef[2].gb, post, pixels);
    if (LAYERED != 0u && !grouped) {
        // Layered with the per-fragment blend, the read's coefficient (grouped, layered_read
        // computes it), one for every channel.
        slot_read[READS * j] = vec4(0.0, coef[0].r, 0.0, 0.0);
    }
}

// Layered, a slot's read is one of seven kinds: the layer texture's kind for the fragment
// (0: plain, 1–4: the block side's summed kernel), SAT_KIND for a merged block of 4×4 and up in
// the wide field (block_reads in splat.glsl: the four corners of its box in the summed-area
// table, with signs + − − +) and WIDE_PAIR_KIND for a 2×2 block there (its four pixels' plain
// kernels where they lie in kernel space, J·(±½, ±½) from its centre). The code says the kind
// and the block side: kind + 8·side, exact in a float.
const uint WIDE_PAIR_KIND = 6u;
float read_code(uint size, bool wide_block) {
    uint kind = !wide_block ? layer_kind(size) : size == 2u ? WIDE_PAIR_KIND : SAT_KIND;
    return float(kind + 8u * size);
}

// Layered: each read kind's texture point and bound (kinds 0–4: layer_point, layer_bound;
// SAT_KIND: the summed-area table's corner 0, the table's half-width), loaded once per
// invocation (walk_slots) and picked per visit by selects, which cost a CPU implementation far
// less than a shared-memory load.
vec3 kind_read0;
vec3 kind_read1;
vec3 kind_read2;
vec3 kind_read3;
vec3 kind_read4;
vec3 kind_read5;
float inv_layer_scale;

void load_kind_reads() {
    inv_layer_scale = 1.0 / layer_scale();
    kind_read0 = vec3(layer_point(0u), layer_bound(0u));
    kind_read1 = vec3(layer_point(1u), layer_bound(1u));
    kind_read2 = vec3(layer_point(2u), layer_bound(2u));
    kind_read3 = vec3(layer_point(3u), layer_bound(3u));
    kind_read4 = vec3(layer_point(4u), layer_bound(4u));
    kind_read5 = vec3(sat_point(), float(layer_header.w) + 0.5);
}

vec3 layer_read_of(float kind) {
    vec3 at = kind_read0;
    at = kind > 0.5 ? kind_read1 : at;
    at = kind > 1.5 ? kind_read2 : at;
    at = kind > 2.5 ? kind_read3 : at;
    at = kind > 3.5 ? kind_read4 : at;
    at = kind > 4.5 ? kind_read5 : at;
    return kind > 5.5 ? kind_read0 : at;
}

// Layered (on axis only): slot j's reads at kernel offset k, times their coefficient; s is the
// slot's J and read code. A visit loads no word for the read: the kind and block side come
// from the code, the kind's point and bound from registers (load_kind_reads), and with the
// depth groups the coefficient from J, since a CPU implementation pays for each shared-memory
// load of every visit (two of seven took 12 % of colonnade's convolution on lavapipe): the
// kernel's weight det J (the local scale's area), times the block's s² pixels, where a wide
// 2×2 block's four reads share them and a box's mean is over its area s²·J₁₁·J₂₂. A wide
// block's four reads are a loop of four in the same visit, not four visits: the loop's trip
// count, uniform in the subgroup, is the one thing such an implementation skips, and a visit's
// loads, reach test and blend cost about three times its read. Each read is clamped to the
// bound, where the slot's zero ring (or the table's edge) lies. Every layered read comes from
// the single floats, which hold the tables too: one texture, so a CPU implementation makes one
// read per step.
vec3 layered_read(uint j, vec2 k, vec4 s, float layer, vec2 extent) {
    float size = floor(s.w * 0.125);
    float kind = s.w - 8.0 * size;
    vec3 at = layer_read_of(kind);
    bool wide = kind > 4.5;
    bool box = wide && kind < 5.5;
    // Steps to the four reads, k ± a ± b: a 2×2 block's pixels lie at J·(±½, ±½), a box's
    // corners at ±(s/2)·(J₁₁, J₂₂).
    vec2 a = box ? vec2(0.5 * size * s.x, 0.0) : 0.5 * s.xy;
    vec2 b = box ? vec2(0.0, 0.5 * size * s.z) : 0.5 * s.yz;
    a = wide ? a : vec2(0.0);
    b = wide ? b : vec2(0.0);
    float coef;
    if (grouped) {
        float area = s.x * s.z - s.y * s.y;
        coef = area * inv_layer_scale * (box ? 1.0 / (s.x * s.z) : wide ? 1.0 : size * size);
    } else {
        coef = slot_read[READS * j].y;
    }
    uint n = wide ? 4u : 1u;
    vec3 w = vec3(0.0);
    for (uint i = 0u; i < n; i++) {
        vec2 corner = vec2((i & 1u) == 0u ? 1.0 : -1.0, i < 2u ? 1.0 : -1.0);
        vec2 q = clamp(k + corner.x * a + corner.y * b, vec2(-at.z), vec2(at.z));
        float sign = box ? corner.x * corner.y : 1.0;
        w += sign * textureLod(layer_sums, vec3((at.xy + q) / extent, layer), 0.0).rgb;
    }
    return coef * w;
}

// Radius levels: read i of slot j at kernel offset d in the region whose origin is `node`.
vec3 one_read(uint j, uint i, vec3 gb_r, vec2 d, vec2 node, float layer, vec2 extent) {
    vec4 at = slot_read[READS * j + i];
    vec3 w = vec3(0.0);
    // Past the block's zero ring lie other blocks: nothing counts there. An unused read's
    // bound is 0. (A GPU skips the read here; a CPU implementation reads and discards.)
    if (all(lessThan(abs(d), vec2(at.z)))) {
        vec3 uvw = vec3((node + at.xy + d) / extent, layer);
        // (Layered reads go through layered_read; the layer texture named here keeps its
        // binding in the shader, whose bindings run without gaps.)
        w = vec3(at.w, gb_r.xy) * (LAYERED != 0u ? textureLod(layer_texture, uvw, 0.0).rgb
                                                 : textureLod(psf_texture, uvw, 0.0).rgb);
    }
    return w;
}

vec3 slot_reads(uint j, vec4 gb0, vec4 gb1, vec2 d, vec2 node, float layer, vec2 extent) {
    return one_read(j, 0u, gb0.xyz, d, node, layer, extent)
         + one_read(j, 1u, vec3(gb0.zw, 0.0), d, node, layer, extent)
         + one_read(j, 2u, gb1.xyz, d, node, layer, extent);
}

// Per-channel kernel weight of slot j at kernel offset k (s: the slot's J and code): the
// reads, off axis the four field nodes mixed bilinearly.
vec3 slot_weight(uint j, vec2 k, vec4 s, vec2 extent, float layer) {
    if (LAYERED != 0u && grouped) {
        // With the depth groups no weight follows the read: slot_gb is not loaded.
        return layered_read(j, k, s, layer, extent);
    }
    vec4 gb0 = slot_gb[2u * j];
    vec4 gb1 = slot_gb[2u * j + 1u];
    vec3 w;
    if (LAYERED != 0u) {
        w = layered_read(j, k, s, layer, extent);
    } else if (OFF_AXIS == 0u) {
        w = slot_reads(j, gb0, gb1, k, vec2(0.0), layer, extent);
    } else {
        vec4 weights = slot_node_weights[j];
        vec4 n01 = slot_nodes[2u * j];
        vec4 n23 = slot_nodes[2u * j + 1u];
        w = vec3(0.0);
        if (weights.x > 0.0) {
            w += weights.x * slot_reads(j, gb0, gb1, k, n01.xy, layer, extent);
        }
        if (weights.y > 0.0) {
            w += weights.y * slot_reads(j, gb0, gb1, k, n01.zw, layer, extent);
        }
        if (weights.z > 0.0) {
            w += weights.z * slot_reads(j, gb0, gb1, k, n23.xy, layer, extent);
        }
        if (weights.w > 0.0) {
            w += weights.w * slot_reads(j, gb0, gb1, k, n23.zw, layer, extent);
        }
    }
    // A merged block under the per-fragment blend: its s² pixels' coverage compounds.
    if (PER_FRAGMENT_BLEND != 0u) {
        w = gb1.w > 1.0 ? vec3(1.0) - pow(max(vec3(1.0) - w, vec3(0.0)), vec3(gb1.w)) : w;
    }
    return w * gb1.z;
}

#include "blend.glsl"

// Each run of eight invocations (a subgroup on lavapipe) takes a patch of 4 × 2 pixels of the
// tile's 8 × 8 (per 8 × 8 quarter when the tile is 16), not a row of 8: a slot visits every
// thread of a subgroup that one of its pixels reaches, and a small kernel's footprint covers
// more of a 4 × 2 patch than of a row (a 5-pixel footprint fills 42 % of the rows it visits,
// 52 % of the patches; the default render's convolution took 10 % less on lavapipe).
const ivec2 PATCH = ivec2(4, 2);
uvec2 patch_origin(uint p) {
    return uvec2(4u * (p & 1u), 2u * (p >> 1u));
}

// The walk: batches of slots, each visited by the subgroups whose patches it reaches.
void walk_slots(uint n, uint base, uint tx, uint ty, vec3 extent) {
    if (LAYERED != 0u) {
        load_kind_reads();
    }
    uint local_index = gl_LocalInvocationIndex;
    uint own_patch = local_index >> 3u;
    if (local_index < 8u) {
        patch_slots[local_index] = uvec3(0u);
    }
    barrier();
    uint start = 0u;
    while (start < n) {
        // 1. Each thread plans one entry's reads and counts its slots.
        bool loaded = start + local_index < n;
        Fragment f;
        ReadPlan plan;
        vec4 reach;
        Footprint fp;
        float post = 1.0;
        float pixels = 1.0;
        uint slots = 0u;
        bool wide_block = false;
        if (loaded) {
            f = load_fragment(entries[base + start + local_index].y);
            vec4 map = fragment_map(f);
            bool scaled = map.w > 0.5;
            fp = footprint_with_map(f, map);
            reach = vec4(f.center, fp.bound, (f.index + 0.5) / extent.z);
            uint size = block_size(f);
            float n_px = float(size * size);
            // Grouped, a merged block's light and the local scale's weight (J's determinant)
            // are linear factors of the reads; the per-fragment blend raises the summed weight
            // to the block's pixel count first.
            float local_weight = map_area(map.xyz);
            float pre = grouped ? (size > 1u ? n_px : 1.0) * local_weight : 1.0;
            post = grouped ? 1.0 : local_weight;
            pixels = !grouped && size > 1u ? n_px : 1.0;
            plan = plan_reads(f, pre);
            slots = plan.slots;
            wide_block = LAYERED != 0u && size > 1u && scaled && block_reads();
        }
        entry_slots[local_index] = slots;
        if (local_index == 0u) {
            unsaturated = 0u;
            batch_taken = 0u;
        }
        barrier();
        // 2. A running sum gives each entry its first slot, in list order.
        [[unroll]] for (uint stride = 1u; stride < 64u; stride <<= 1u) {
            uint add = local_index >= stride ? entry_slots[local_index - stride] : 0u;
            barrier();
            entry_slots[local_index] += add;
            barrier();
        }
        uint first = entry_slots[local_index] - slots;
        bool fits = loaded && first + slots <= SLOTS;
        // 3. The entries that fit fill their slots and mark the patches they may reach (the
        // pixels' own test below is exact).
        if (fits) {
            atomicAdd(batch_taken, 1u);
            float code = read_code(block_size(f), wide_block);
            [[unroll]] for (uint k = 0u; k < 3u; k++) {
                if (k < slots) {
                    fill_slot(first + k, f, plan, k, reach, fp.map, post, pixels, code);
                }
            }
            if (OFF_AXIS != 0u) {
                uvec4 nodes;
                vec4 weights;
                field_corners(f.center, nodes, weights);
                vec4 n01 = LAYERED != 0u
                    ? vec4(vec2(layer_node_origin(nodes.x)), vec2(layer_node_origin(nodes.y)))
                    : vec4(vec2(node_origin(nodes.x)), vec2(node_origin(nodes.y)));
                vec4 n23 = LAYERED != 0u
                    ? vec4(vec2(layer_node_origin(nodes.z)), vec2(layer_node_origin(nodes.w)))
                    : vec4(vec2(node_origin(nodes.z)), vec2(node_origin(nodes.w)));
                [[unroll]] for (uint k = 0u; k < 3u; k++) {
                    if (k < slots) {
                        slot_nodes[2u * (first + k)] = n01;
                        slot_nodes[2u * (first + k) + 1u] = n23;
                        slot_node_weights[first + k] = weights;
                    }
                }
            }
            // Bits first … first + slots − 1 of the 96-bit patch masks.
            uvec3 index = uvec3(0u, 32u, 64u);
            uvec3 lo = uvec3(clamp(ivec3(first) - ivec3(index), ivec3(0), ivec3(32)));
            uvec3 hi = uvec3(clamp(ivec3(first + slots) - ivec3(index), ivec3(0), ivec3(32)));
            uvec3 below_hi = mix(uvec3(0xFFFFFFFFu), (uvec3(1u) << hi) - 1u, lessThan(hi, uvec3(32u)));
            uvec3 below_lo = mix(uvec3(0xFFFFFFFFu), (uvec3(1u) << lo) - 1u, lessThan(lo, uvec3(32u)));
            uvec3 bits = below_hi & ~below_lo;
            [[unroll]] for (uint p = 0u; p < 8u; p++) {
                // Whether the footprint's columns in either of the patch's two rows meet its
                // four columns (footprint_columns; no short-circuit: each `||` is a branch,
                // which a CPU implementation's compiler is slow to take apart).
                uint reached = 0u;
                [[unroll]] for (uint k = 0u; k < PIXELS; k++) {
                    ivec2 at = ivec2(uvec2(tx, ty) * TILE + patch_origin(p)
                                     + 8u * uvec2(k % PER_AXIS, k / PER_AXIS));
                    [[unroll]] for (int row = 0; row < PATCH.y; row++) {
                        ivec2 x = footprint_columns(fp, f.center, at.y + row);
                        reached |= uint(max(x.x, at.x) <= min(x.y, at.x + PATCH.x - 1));
                    }
                }
                if (reached != 0u) {
                    atomicOr(patch_slots[p].x, bits.x);
                    atomicOr(patch_slots[p].y, bits.y);
                    atomicOr(patch_slots[p].z, bits.z);
                }
            }
        }
        barrier();
        // 4. The slots that reach any pixel of this subgroup, in list order: a loop uniform in
        // the subgroup (lavapipe runs it until all its threads leave it).
        uvec3 todo = subgroupOr(patch_slots[own_patch]);
        while (any(notEqual(todo, uvec3(0u)))) {
            bool in_x = todo.x != 0u;
            bool in_y = !in_x && todo.y != 0u;
            bool in_z = !in_x && !in_y;
            uint j = in_x ? uint(findLSB(todo.x))
                   : in_y ? 32u + uint(findLSB(todo.y)) : 64u + uint(findLSB(todo.z));
            todo.x = in_x ? todo.x & (todo.x - 1u) : todo.x;
            todo.y = in_y ? todo.y & (todo.y - 1u) : todo.y;
            todo.z = in_z ? todo.z & (todo.z - 1u) : todo.z;
            vec4 g = slot_reach[j];
            vec4 color = slot_color[j];
            vec4 s = slot_scale[j];
            [[unroll]] for (uint q = 0u; q < PIXELS; q++) {
                vec2 d = centre[q] - g.xy;
                // The footprint's test (fragment_footprint), in kernel space.
                vec2 k = map_offset(s.xyz, d);
                if (abs(k.x) < g.z && abs(k.y) < g.z) {
                    vec3 w = slot_weight(j, k, s, extent.xy, g.w);
                    uvec4 hidden = slot_hidden[j];
                    vec3 share = HIDDEN == 0u ? vec3(1.0)
                        : pupil_share(hidden.x, uintBitsToFloat(hidden.yzw),
                                      pupil_inner(hidden.x), d);
                    if (grouped) {
                        if (last[q] >= 0.0 && abs(color.w - last[q]) > frame.group_tolerance_d) {
                            close_group(C[q], A[q], Cg[q], Ag[q], Gg[q]);
                        }
                        Cg[q] += (w * share) * color.rgb;
                        Ag[q] += w;
                        Gg[q] += w * share;
                        last[q] = color.w;
                    } else {
                        C[q] += (vec3(1.0) - A[q]) * (w * share) * color.rgb;
                        A[q] += (vec3(1.0) - A[q]) * (w * share);
                    }
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
        start += batch_taken;
        if (local_index < 8u) {
            patch_slots[local_index] = uvec3(0u);
        }
        barrier();
        if (done) {
            break;
        }
    }

}

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
    [[unroll]] for (uint q = 0u; q < PIXELS; q++) {
        uvec2 pixel = uvec2(tx, ty) * TILE + patch_origin(gl_LocalInvocationIndex >> 3u)
                    + uvec2(gl_LocalInvocationIndex & 3u, (gl_LocalInvocationIndex >> 2u) & 1u)
                    + 8u * uvec2(q % PER_AXIS, q / PER_AXIS);
        centre[q] = vec2(pixel) + 0.5;
        C[q] = vec3(0.0);
        A[q] = vec3(0.0);
        Cg[q] = vec3(0.0);
        Ag[q] = vec3(0.0);
        Gg[q] = vec3(0.0);
        last[q] = -1.0;
    }
    walk_slots(n, base, tx, ty, vec3(LAYERED != 0u ? textureSize(layer_sums, 0)
                                               : textureSize(psf_texture, 0)));

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
