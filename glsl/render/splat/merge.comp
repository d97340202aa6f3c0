#version 460
// Merges blocks of strongly blurred fragments into one fragment, in place: the merged
// fragment takes the block's top-left slot, the others are marked merged away (size 0).
// One dispatch per block size (`MergePush` in src/render/splat/merge.rs): 2 merges 2×2 single
// pixels, 4 merges 2×2 already-merged 2×2 blocks, and so on up to 32. Thresholds scale with
// the block's smallest blur radius: the more blur, the less a difference in colour or dioptre
// can show.
#extension GL_GOOGLE_include_directive : require
#define FRAME_BINDING 5
#include "splat.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform MergePush {
    uint block_size;       // side of the blocks this dispatch makes (2, 4, … 32)
    // k: a block of side s merges only when every child's kernels are at least k·s in radius
    // (0: any side, the seed paper's rule).
    float blur_per_block;
    // Largest misplacement (px) of a merged block's edge pixels in kernel space, in the wide
    // field (`MergeSettings::scale_error_px`).
    float scale_error_px;
} push;

// Per object distance o: natural radius per channel (xyz) and the smallest core radius (w) at
// radii[o]; the smallest peak radius over the channels at radii[object_count + o].x, and the
// radius of the highest level the kernels hold there at .y (src/psf/level_band.rs).
layout(std430, binding = 0) readonly buffer Radii { vec4 radii[]; };
FRAGMENT_BUFFERS(1, 2, 3, 4, )
FRAGMENT_LOAD
FRAGMENT_STORE

// Core radius (√2·r50) of a fragment's kernels, interpolated like its radius.
float core_radius(Fragment f) {
    uint i0 = uint(floor(f.index));
    uint i1 = min(i0 + 1u, frame.object_count - 1u);
    return mix(radii[i0].w, radii[i1].w, f.index - float(i0));
}

// Peak radius (1/√(π·peak)) of a fragment's kernels, interpolated like its radius.
float peak_radius(Fragment f) {
    uint i0 = uint(floor(f.index));
    uint i1 = min(i0 + 1u, frame.object_count - 1u);
    uint n = frame.object_count;
    return mix(radii[n + i0].x, radii[n + i1].x, f.index - float(i0));
}

float min3(vec3 v) { return min(v.x, min(v.y, v.z)); }
float max3(vec3 v) { return max(v.x, max(v.y, v.z)); }

void main() {
    uint size = push.block_size;
    uint child = size / 2u;
    uvec2 block = gl_GlobalInvocationID.xy;
    uvec2 origin = block * size;
    if (origin.x + size > frame.width || origin.y + size > frame.height) {
        return; // partial blocks at the right and bottom edges stay as they are
    }
    uint ids[4];
    ids[0] = origin.y * frame.width + origin.x;
    ids[1] = ids[0] + child;
    ids[2] = ids[0] + child * frame.width;
    ids[3] = ids[2] + child;
    Fragment f[4];
    for (int k = 0; k < 4; k++) {
        f[k] = load_fragment(ids[k]);
        if (f[k].size != child) {
            return; // a child was not (or differently) merged
        }
    }
    // How blurred the block is: its kernels' smallest core radius, not their full extent (a
    // PSF with a sharp core and a wide flare must not merge: averaging would smear the core).
    float r_min = 1e30;
    float r_peak = 1e30;
    for (int k = 0; k < 4; k++) {
        r_min = min(r_min, min(min3(f[k].radius), core_radius(f[k])));
        r_peak = min(r_peak, peak_radius(f[k]));
    }
    // Three conditions, each a bound on what averaging the block changes. Its pixels keep
    // their kernel (the block reads the kernel summed over its pixels, below), so what merging
    // averages is their colours and depths: (1) the block is no wider than the blur allows,
    // s ≤ r / k (`blur_per_block`, 0: any side) and r at least the minimum radius;
    // (2) colours: a kernel's rim crossing the block splits it, and the part inside carries
    // its own colour, not the block's mean; with children whose colours differ by Δc that
    // misplaces about Δc·s²/4 of colour, so the pixel moves by about Δc·s²·h/4, h the rim's
    // height: at most the kernel's peak, 1/(π·r_peak²) (r_peak, the peak radius, is the
    // natural radius for a defocus disc and smaller for a line focus, a caustic ring or a
    // sharp core). A smooth gradient cancels around the rim; a step does not. The block
    // merges when Δc·(s/r_peak)²/(4π) is at most the error budget ε (`merge_color_error`).
    // (3) the depths'
    // summed spread within its tolerance per pixel of blur, and the whole block in one depth
    // group of the blend, so the merged fragment joins the group its pixels would have.
    if (r_min < max(frame.merge_min_radius, push.blur_per_block * float(size))) {
        return;
    }
    // (4) In the wide field the block's pixels lie J·δ apart in kernel space (J = c_t·I +
    // (c_r − c_t)·e·eᵀ, the local scale: c_r = cos²θ radially, c_t = cos θ tangentially), not
    // δ. Layered with the depth-group blend, a merged block reads its pixels where they lie
    // (block_reads in splat.glsl, layer_atlas.glsl): no bound. Otherwise its one read (the block-summed
    // kernel, or a 2×2 block's bilinear midpoint) assumes δ and misplaces its edge pixels by
    // (1 − c_r)·s/2; true PSFs vary texel to texel, so even a 2×2 block off by 0.1–0.4 px put a
    // two-pixel pattern into colonnade's blurred lamps. Merge only where that is at most
    // push.scale_error_px (the seed's rule is J = I everywhere: the narrow field).
    vec3 s = local_scale(vec2(origin) + 0.5 * float(size));
    float c = s.z * s.z;
    if (!block_reads() && (1.0 - c) * 0.5 * float(size) > push.scale_error_px) {
        return;
    }
    float lo = 1e30;
    float hi = -1e30;
    for (int k = 0; k < 4; k++) {
        lo = min(lo, f[k].dioptre);
        hi = max(hi, f[k].dioptre);
    }
    if (hi - lo > frame.group_tolerance_d) {
        return;
    }
    float blur_per_side = min(r_min, r_peak) / float(size);
    // 4π·ε·(r/s)²
    float color_bound = 12.566371 * frame.merge_color_error * blur_per_side * blur_per_side;
    float dioptre_spread = 0.0;
    for (int a = 0; a < 4; a++) {
        for (int b = a + 1; b < 4; b++) {
            vec3 dc = abs(f[a].color - f[b].color);
            if (max3(dc) > color_bound) {
                return;
            }
            dioptre_spread += abs(f[a].index - f[b].index) * frame.dioptre_step;
        }
    }
    if (dioptre_spread >= 6.0 * frame.merge_dioptre_tolerance * r_min) {
        return;
    }
    Fragment m;
    m.color = 0.25 * (f[0].color + f[1].color + f[2].color + f[3].color);
    m.depth = min(min(f[0].depth, f[1].depth), min(f[2].depth, f[3].depth));
    m.index = 0.25 * (f[0].index + f[1].index + f[2].index + f[3].index);
    vec3 r_max = max(max(f[0].radius, f[1].radius), max(f[2].radius, f[3].radius));
    // The block spreads its light over size × size pixels, each pixel by the same kernel from
    // its own position. A 2×2 block's centre lies half a pixel off the pixel grid, so the
    // convolution's bilinear lookup there averages the kernel over the four pixels' offsets:
    // the kernel itself is exact. A block of 4×4 and up reads its level's kernel summed over
    // the block (glsl/common/atlas.glsl, kernel_slot): exact too, the kernel's shape and any
    // centroid offset kept. The radius stays the children's, which picks the levels.
    m.radius = max(max(f[0].radius, f[1].radius), max(f[2].radius, f[3].radius));
    // Within the levels the kernels hold at the block's distance: a block whose pixels span
    // more dioptres than the band's window (a group tolerance far above the default) would
    // otherwise read levels that are not there.
    uint t0 = uint(floor(m.index));
    uint t1 = min(t0 + 1u, frame.object_count - 1u);
    uint n = frame.object_count;
    m.radius = min(m.radius, vec3(min(radii[n + t0].y, radii[n + t1].y)));
    m.center = vec2(origin) + 0.5 * float(size);
    m.size = size;
    m.dioptre = 0.25 * (f[0].dioptre + f[1].dioptre + f[2].dioptre + f[3].dioptre);
    store_fragment(ids[0], m);
    for (int k = 1; k < 4; k++) {
        f[k].size = 0u;
        store_fragment(ids[k], f[k]);
    }
}
