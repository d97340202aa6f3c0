// Off-axis kernels (src/render/splat/field.rs): the PSF texture holds one region per node of a
// lattice of field angles (h, v) (glsl/common/atlas.glsl); a fragment's kernel mixes the four
// nodes around the direction of its pixel. On axis the lattice is one node.
// The including pass declares `field_header[2]` and `node_radii[]` (the Field buffer):
//   field_header[0] = (nodes along h, nodes along v, 0, 0),
//   field_header[1] = (first h, h step, first v, v step) in degrees,
//   node_radii[node · No + o] = the node's natural radius per channel at object distance o.
#ifndef OCULAR_FIELD_GLSL
#define OCULAR_FIELD_GLSL

uint field_nodes() {
    return uint(field_header[0].x) * uint(field_header[0].y);
}

// Field angles (h, v) in degrees of a screen point: right and up are positive, and a pixel
// at (x, y) from the centre looks along (x/f, y/f, 1) (src/eye/field.rs).
vec2 field_deg(vec2 c) {
    vec2 u = (c - 0.5 * vec2(frame.width, frame.height)) / frame.focal_px;
    return degrees(atan(vec2(u.x, -u.y)));
}

// The four lattice nodes around screen point c (h-major indices) and their bilinear weights,
// clamped at the lattice's edges.
void field_corners(vec2 c, out uvec4 nodes, out vec4 weights) {
    vec2 n = field_header[0].xy;
    vec2 t = clamp((field_deg(c) - field_header[1].xz) / field_header[1].yw, vec2(0.0), n - 1.0);
    vec2 lo = min(floor(t), max(n - 2.0, vec2(0.0)));
    vec2 f = t - lo;
    vec2 hi = min(lo + 1.0, n - 1.0);
    uint nv = uint(n.y);
    uvec2 l = uvec2(lo);
    uvec2 h = uvec2(hi);
    nodes = uvec4(l.x * nv + l.y, l.x * nv + h.y, h.x * nv + l.y, h.x * nv + h.y);
    weights = vec4((1.0 - f.x) * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * (1.0 - f.y), f.x * f.y);
}

#endif
