// Declarations shared by the tiled PSF-splatting passes (src/render/splat/).
#ifndef OCULAR_SPLAT_GLSL
#define OCULAR_SPLAT_GLSL

// One screen-space fragment: a pixel, or a merged block of size × size pixels.
// Mirrors `Fragment` in src/render/splat/mod.rs (std430, 48 bytes).
struct Fragment {
    vec3 color;    // linear RGB
    float depth;   // metres along the view axis: the sort key
    vec3 radius;   // blur radius in pixels per channel (R, G, B), clamped to Rmax
    float index;   // continuous index on the object-dioptre axis of the PSF texture
    vec2 center;   // footprint centre in pixels (a pixel's centre is x + 0.5)
    uint size;     // bits 0–6: 1 = single pixel, 2 or 4 = merged block, 0 = merged away or
                   // empty; bit 7: a hidden-layer fragment, whose bits 8–31 say which of
                   // its rays reach the pupil (pupil_share)
    float dioptre; // vergence along the pixel's ray (D, unclamped): the blend's grouping key
};

// Per-frame constants, identical for every pass and every dispatch of a frame: a uniform
// buffer the host writes once per frame through its mapping (values that change between the
// dispatches of a frame are each pass's own push constants). Each shader defines FRAME_BINDING,
// a binding number of its own, before including this file; passes bind the block by its name. std140: scalars only, so the layout is that of
// `FrameUniform` in src/render/splat/mod.rs (a vec3 or an array here would need padding there).
#ifndef FRAME_BINDING
#error "define FRAME_BINDING (the binding of the frame's uniform block) before splat.glsl"
#endif
layout(std140, binding = FRAME_BINDING) uniform FrameUniform {
    uint width;
    uint height;
    uint tiles_x;
    uint tiles_y;
    uint tile_size;
    uint object_count;     // No
    uint max_radius;       // Rmax
    uint fragment_count;   // width * height * layers
    float dioptre_min;
    float dioptre_step;
    float merge_min_radius;
    float merge_color_error;
    float merge_dioptre_tolerance;
    float focal_px;        // (H/2)/tan(fov_y/2)
    float group_tolerance_d;
    uint blend_mode;       // 0 = depth groups, 1 = the seed paper's per-fragment blend
    uint wide_field;       // 1 = vergence along rays and kernels at the local pinhole scale
    float saturation_epsilon; // convolution stops once every pixel's coverage is ≥ 1 − ε
    uint fragments_per_chunk; // see FRAGMENT_BUFFERS
    uint layers;           // depth layers stacked in the inputs and fragments (1 = visible only)
    // 1: the convolution reads each object distance's own kernel from the layer texture
    // (glsl/common/layer_atlas.glsl), one read for all channels; 0: the radius levels.
    uint layered;
    // Layered: the largest radius step (px) between neighbouring object distances, which a
    // fragment between them may reach past its own radius; 0 otherwise.
    float radius_step;
} frame;

// A frame's fragments live in one buffer, bound as four consecutive ranges of
// frame.fragments_per_chunk fragments each (src/render/splat/fragments.rs): a 3840×2160 frame
// holds 380 MiB of fragments and a device may bind as little as 128 MiB per binding. A pass
// declares the four bindings with FRAGMENT_BUFFERS and reads and writes through
// load_fragment / store_fragment (FRAGMENT_LOAD, FRAGMENT_STORE).
#define FRAGMENT_BUFFERS(B0, B1, B2, B3, QUALIFIER)                                          \
    layout(std430, binding = B0) QUALIFIER buffer Fragments0 { Fragment fragments0[]; };     \
    layout(std430, binding = B1) QUALIFIER buffer Fragments1 { Fragment fragments1[]; };     \
    layout(std430, binding = B2) QUALIFIER buffer Fragments2 { Fragment fragments2[]; };     \
    layout(std430, binding = B3) QUALIFIER buffer Fragments3 { Fragment fragments3[]; };

#define FRAGMENT_LOAD                                                                        \
    Fragment load_fragment(uint i) {                                                         \
        uint chunk = i / frame.fragments_per_chunk;                                          \
        uint j = i - chunk * frame.fragments_per_chunk;                                      \
        if (chunk == 0u) return fragments0[j];                                               \
        if (chunk == 1u) return fragments1[j];                                               \
        if (chunk == 2u) return fragments2[j];                                               \
        return fragments3[j];                                                                \
    }

#define FRAGMENT_STORE                                                                       \
    void store_fragment(uint i, Fragment f) {                                                \
        uint chunk = i / frame.fragments_per_chunk;                                          \
        uint j = i - chunk * frame.fragments_per_chunk;                                      \
        if (chunk == 0u) fragments0[j] = f;                                                  \
        else if (chunk == 1u) fragments1[j] = f;                                             \
        else if (chunk == 2u) fragments2[j] = f;                                             \
        else fragments3[j] = f;                                                              \
    }

// The kernel layout at a screen point (see src/render/projection.rs): xy = radial unit
// vector, z = cos θ. A screen offset d maps to the kernel offset
// cos θ·d + (cos²θ − cos θ)(d·e)e, and weights scale by cos³θ.
vec3 local_scale(vec2 center) {
    if (frame.wide_field == 0u) {
        return vec3(1.0, 0.0, 1.0);
    }
    vec2 u = center - 0.5 * vec2(frame.width, frame.height);
    float rho = length(u);
    if (rho < 1e-6) {
        return vec3(1.0, 0.0, 1.0);
    }
    return vec3(u / rho, frame.focal_px / sqrt(frame.focal_px * frame.focal_px + rho * rho));
}

// Radial and tangential shrink for a kernel of radius r: (cos²θ, cos θ) from 1.5 px up,
// none below 0.5 px (an in-focus kernel keeps its pixel), linear between; continuous in
// field angle and radius (src/render/projection.rs).
vec2 shrink_for_radius(float cos_theta, float r) {
    float t = clamp(r - 0.5, 0.0, 1.0);
    return vec2(1.0) + t * (vec2(cos_theta * cos_theta, cos_theta) - vec2(1.0));
}

// The map of a screen offset d to its kernel offset J·d, J = c_t·I + (c_r − c_t)·e·eᵀ (e: the
// radial unit vector, c: the (radial, tangential) shrink): symmetric, so (J₁₁, J₁₂, J₂₂).
vec3 local_map(vec2 e, vec2 c) {
    float r = c.x - c.y;
    return vec3(c.y + r * e.x * e.x, r * e.x * e.y, c.y + r * e.y * e.y);
}

// J·d for the map m = (J₁₁, J₁₂, J₂₂).
vec2 map_offset(vec3 m, vec2 d) {
    return vec2(m.x * d.x + m.y * d.y, m.y * d.x + m.z * d.y);
}

// det J: the kernel's weight per screen pixel (cos³θ in full).
float map_area(vec3 m) {
    return m.x * m.z - m.y * m.y;
}

// Whether a merged block in the wide field reads its pixels where they lie in kernel space
// (glsl/common/layer_atlas.glsl: the layer kernels with the depth-group blend), rather than
// one read that assumes them one texel apart (merge.comp bounds that read's misplacement).
bool block_reads() {
    return frame.layered != 0u && frame.blend_mode == 0u;
}

// Radius levels of the kernel blocks (src/psf/kernels.rs): quarter pixels up to 2 px, whole
// pixels beyond; level l has a block of radius ceil(level_radius(l)).
const uint LEVELS_PER_PX = 4u;
const uint FINE_UNTIL_PX = 2u;
const uint FINE_LEVELS = LEVELS_PER_PX * FINE_UNTIL_PX;

uint level_count() {
    return frame.max_radius <= FINE_UNTIL_PX ? frame.max_radius * LEVELS_PER_PX + 1u
                                             : FINE_LEVELS + (frame.max_radius - FINE_UNTIL_PX) + 1u;
}

float level_radius(uint level) {
    return level <= FINE_LEVELS ? float(level) / float(LEVELS_PER_PX)
                                : float(FINE_UNTIL_PX + level - FINE_LEVELS);
}

uint level_block_radius(uint level) {
    return level <= FINE_LEVELS ? (level + LEVELS_PER_PX - 1u) / LEVELS_PER_PX
                                : FINE_UNTIL_PX + level - FINE_LEVELS;
}

// Continuous level of a kernel radius (what the convolution interpolates on).
vec3 level_of_radius(vec3 r) {
    vec3 fine = r * float(LEVELS_PER_PX);
    vec3 coarse = vec3(float(FINE_LEVELS)) + r - vec3(float(FINE_UNTIL_PX));
    return mix(fine, coarse, step(vec3(float(FINE_UNTIL_PX)) + 1e-6, r));
}

const uint HIDDEN_FRAGMENT = 0x80u;
// 8 pupil directions × 3 rings of equal area (bit 3·direction + ring).
const uint ALL_RAYS = 0xFFFFFFu;

uint block_size(Fragment f) {
    return f.size & 0x7Fu;
}

// The inner ring's mean over the eight directions of a hidden fragment's ray mask (`size`):
// what the pixel under its centre receives. Per fragment, not per pixel.
float pupil_inner(uint size) {
    // bits 3·i, i = 0 … 7: ring 0 of every direction
    return float(bitCount((size >> 8u) & 0x249249u)) * 0.125;
}

// Per channel, the share of a fragment's light at pixel offset d that reaches the pupil. A
// hidden-layer fragment's light through the pupil point at ρ·a in direction e lands near
// ρ·r·e from its centre (r: that channel's blur radius; the fragments pass oriented the rays
// to the kernel's side) and arrives only if that ray passed the nearer surfaces
// (glsl/render/splat/fragments.comp, pupil_visibility). Bits 3·i + l: direction i·45°, ring l
// of three of equal pupil area. A channel in focus (r below half a pixel) lands all its rays on
// its own pixel: its light arrives if any ray passes, and the nearer groups' coverage takes
// the blocked share; the pixel under the centre (|d| < ½) takes the inner ring's mean, since
// no direction is defined there; between ½ and 1½ px of blur the two mix, so the share is
// continuous in the radius. (Before, one radius for all channels made an in-focus green
// channel depend on the single ray of direction 0 when red or blue were blurred.)
vec3 pupil_share(uint size, vec3 radius, float inner, vec2 d) {
    uint rays = size >> 8u;
    if ((size & HIDDEN_FRAGMENT) == 0u || rays == ALL_RAYS) {
        return vec3(1.0);
    }
    if (rays == 0u) {
        return vec3(0.0);
    }
    float dd = dot(d, d);
    uint direction = uint(int(round(atan(d.y, d.x) * (4.0 / 3.14159265358979))) & 7);
    // Written out per channel: a loop would count against lavapipe's loop-iteration cap.
    vec3 r = max(radius, vec3(1e-3));
    uvec3 ring = min(uvec3(3.0 * dd / (r * r)), uvec3(2u));
    uvec3 ray = (uvec3(rays) >> (uvec3(3u * direction) + ring)) & 1u;
    vec3 seen = dd < 0.25 ? vec3(inner) : vec3(ray);
    return mix(vec3(1.0), seen, clamp(r - 0.5, vec3(0.0), vec3(1.0)));
}

// Where a fragment's kernel can be non-zero, in kernel space: its reads at kernel offset
// k = J·d of a screen offset d (J: the local scale's map, (J₁₁, J₁₂, J₂₂), I where none
// applies) are zero unless |k.x| and |k.y| are below its bound. Tested in kernel space, a
// kernel off the centre of a wide frame covers the parallelogram J⁻¹·square on the screen;
// the square around that, what the reach test was, held 1.3 times as many pairs on colonnade's
// 60° frame (validation.md, "The reach test in kernel space"), each extra one read as zeros
// and able to split the pixel's depth groups. One bound for both axes, so that a visit tests it without computing it.
struct Footprint {
    vec3 map;     // J
    float bound;  // exclusive half-side of the square in kernel space
};

// The bound of a kernel of block radius r (footprint_radius) at local map j, for a fragment of
// block side `size`; wide_block: a merged block that reads its pixels where they lie
// (block_reads, off the centre).
float footprint_bound(float r, vec3 j, uint size, bool wide_block) {
    // The block-summed kernel, (2r + s)² texels; in the wide field the box of half-sides
    // (s/2)·(J₁₁, J₂₂) over the plain kernel, whose texels cover r + ½ each way.
    float box = r + 0.5 + 0.5 * float(size) * (wide_block ? max(j.x, j.z) : 1.0);
    // Bilinear reads reach one texel past the block; a wide 2×2 block reads its four pixels'
    // kernels at J·(±½, ±½) from its centre.
    float pair = r + 1.0 + (wide_block ? 0.5 * (abs(j.y) + max(abs(j.x), abs(j.z))) : 0.0);
    return size >= 4u ? box : size == 2u ? pair : r + 1.0;
}

// Layered, the two object distances' kernels around the fragment's are each as wide as their
// own radius, which lies within radius_step of the fragment's; a kernel of radius r fills the
// (2⌈r⌉+1)² texels of its block.
float footprint_radius(Fragment f) {
    return ceil(max(f.radius.r, max(f.radius.g, f.radius.b)) + frame.radius_step);
}

// The local scale's map of a fragment (xyz), I where none applies, and 1 where it applies
// (w): the largest channel radius decides how much of it applies (shrink_for_radius).
vec4 fragment_map(Fragment f) {
    vec3 s = local_scale(f.center);
    vec2 c = shrink_for_radius(s.z, max(f.radius.r, max(f.radius.g, f.radius.b)));
    return c.x < 1.0 ? vec4(local_map(s.xy, c), 1.0) : vec4(1.0, 0.0, 1.0, 0.0);
}

// The footprint of fragment f whose map (fragment_map) is j.
Footprint footprint_with_map(Fragment f, vec4 j) {
    return Footprint(j.xyz, footprint_bound(footprint_radius(f), j.xyz, block_size(f),
                                            j.w > 0.5 && block_reads()));
}

Footprint fragment_footprint(Fragment f) {
    return footprint_with_map(f, fragment_map(f));
}

// Half-extents on the screen of the footprint: J⁻¹ applied to the bound, per axis.
vec2 footprint_extent(Footprint fp) {
    vec3 m = fp.map;
    return fp.bound * vec2(m.z + abs(m.y), abs(m.y) + m.x) / map_area(m);
}

// The open interval of screen offsets d.x in row d.y that lie inside the footprint (empty
// when lo ≥ hi): within both of J's rows' strips.
vec2 footprint_row(Footprint fp, float dy) {
    vec3 m = fp.map;
    // (the same reciprocals for every row: a compiler computes them once)
    vec2 x = vec2(-fp.bound - m.y * dy, fp.bound - m.y * dy) * (1.0 / m.x);
    if (abs(m.y) > 1e-7) {
        vec2 y = vec2(-fp.bound - m.z * dy, fp.bound - m.z * dy) * (1.0 / m.y);
        y = m.y > 0.0 ? y : y.yx;
        x = vec2(max(x.x, y.x), min(x.y, y.y));
    } else if (abs(m.z * dy) >= fp.bound) {
        x = vec2(0.0);
    }
    return x;
}

// Inclusive pixel columns of row py (a pixel's centre is px + 0.5) inside the footprint of a
// fragment centred at `centre`, clipped to the frame (x0 > x1: none).
ivec2 footprint_columns(Footprint fp, vec2 centre, int py) {
    vec2 x = footprint_row(fp, float(py) + 0.5 - centre.y) + centre.x - 0.5;
    ivec2 p = ivec2(int(floor(x.x)) + 1, int(ceil(x.y)) - 1);
    return ivec2(max(p.x, 0), min(p.y, int(frame.width) - 1));
}

// Inclusive rectangle (x0, y0, x1, y1) of the rows, and of the columns at most, whose pixels
// the footprint can reach. Empty (x0 > x1) if off screen.
ivec4 fragment_pixels(Fragment f, Footprint fp) {
    vec2 h = footprint_extent(fp);
    // Pixel px has centre px + 0.5; it is reached when |px + 0.5 − c| < h on both axes.
    ivec2 p0 = ivec2(floor(f.center - 0.5 - h)) + 1;
    ivec2 p1 = ivec2(ceil(f.center - 0.5 + h)) - 1;
    p0 = max(p0, ivec2(0));
    p1 = min(p1, ivec2(int(frame.width) - 1, int(frame.height) - 1));
    if (p0.x > p1.x || p0.y > p1.y) {
        return ivec4(0, 0, -1, -1);
    }
    return ivec4(p0, p1);
}

// Filtered texture reads the pixel walk (glsl/render/splat/convolve.comp) makes for one (pixel,
// fragment) pair within reach, at most, over `nodes` field nodes: what a GPU's convolution
// spends its time on, where kernel evaluations count the pairs alone (`ocular bench`). Layered:
// one, or four for a merged block that reads its pixels where they lie in the wide field
// (block_reads). Radius levels: the levels its channels' radii span (one to three, or two per
// channel when they span more). Reads past a kernel's bound are skipped by the walk and
// counted here.
uint reads_per_evaluation(Fragment f, uint nodes) {
    float r = max(f.radius.r, max(f.radius.g, f.radius.b));
    if (frame.layered != 0u) {
        bool wide = shrink_for_radius(local_scale(f.center).z, r).x < 1.0;
        return wide && block_size(f) > 1u && block_reads() ? 4u : 1u;
    }
    vec3 level = level_of_radius(f.radius);
    float base = min(floor(level.r), min(floor(level.g), floor(level.b)));
    float top = max(ceil(level.r), max(ceil(level.g), ceil(level.b)));
    uint per_node;
    if (top - base <= 2.0) {
        per_node = 1u + uint(top - base);
    } else {
        bvec3 between = greaterThan(level - floor(level), vec3(0.0));
        per_node = 3u + uint(between.r) + uint(between.g) + uint(between.b);
    }
    return per_node * nodes;
}

// Per tile row ty of the footprint's rows, the inclusive range of tile columns whose pixels it
// reaches (x > y: none): the union over the row's pixel rows of their columns, one interval
// since the footprint is convex. tile_count and tile_fill take the same tiles from it.
ivec2 footprint_tile_columns(Footprint fp, vec2 centre, ivec4 pixels, int ty) {
    int t = int(frame.tile_size);
    int y0 = max(pixels.y, ty * t);
    int y1 = min(pixels.w, ty * t + t - 1);
    ivec2 span = ivec2(1 << 30, -1);
    for (int py = y0; py <= y1; py++) {
        ivec2 x = footprint_columns(fp, centre, py);
        if (x.x <= x.y) {
            span = ivec2(min(span.x, x.x), max(span.y, x.y));
        }
    }
    return span.x <= span.y ? span / t : ivec2(0, -1);
}

#endif
