// The blend's steps both convolution walks share (src/render/blend.rs is the CPU's):
// closing a depth group, and the fill behind a near fragment. The including shader declares
// the frame block and FRAGMENT_LOAD first.
#ifndef OCULAR_BLEND_GLSL
#define OCULAR_BLEND_GLSL

// Composites the open group behind what is already there and empties it. Its coverage is
// its kernels' summed weight (at most 1); its light is the mean over the weight that reaches
// the pupil, which differs only where a hidden-layer fragment's rays are blocked
// (pupil_share): the nearer groups' coverage already removed the blocked part of the pupil,
// so the hidden light fills the rest with what those rays really meet. A group none of whose
// light gets through takes no coverage.
void close_group(inout vec3 C, inout vec3 A, inout vec3 Cg, inout vec3 Ag, inout vec3 Gg) {
    vec3 reaches = step(vec3(1e-30), Gg);
    vec3 coverage = min(Ag, vec3(1.0)) * reaches;
    C += (vec3(1.0) - A) * coverage * Cg / max(Gg, vec3(1e-30));
    A += (vec3(1.0) - A) * coverage;
    Cg = vec3(0.0);
    Ag = vec3(0.0);
    Gg = vec3(0.0);
}

// What a near fragment hides is unknown where no hidden layer holds it, and
// dividing by the coverage would fill the hole behind it with its own light (a point light
// before a distant background gains up to a fifth of its energy). What lies behind is the
// surface that surrounds the near one from behind: along eight directions from the pixel, past
// the first step to a farther vergence (more than the group tolerance) within the pixel's own
// blur reach (the hole is as wide as its kernel), as many pixels of that surface as the reach.
// Their mean colour (the best guess of a texture whose continuation is hidden) fills the
// coverage the pixel's groups leave (with hidden layers, what they left); a pixel with no such
// neighbour (a surface at the back, or the frame's border) keeps the division (so an empty
// hidden layer changes nothing). src/render/blend.rs::background_behind is the CPU's.
bool background_behind(uvec2 pixel, out vec3 colour) {
    colour = vec3(0.0);
    if (frame.blend_mode != 0u) {
        return false;
    }
    Fragment own = load_fragment(pixel.y * frame.width + pixel.x);
    int reach = int(ceil(max(own.radius.r, max(own.radius.g, own.radius.b)))) + 1;
    float found = 0.0;
    for (uint i = 0u; i < 8u; i++) {
        ivec2 step_px = ivec2(round(vec2(cos(float(i) * 0.78539816), sin(float(i) * 0.78539816))));
        float previous = own.dioptre;
        int taken = 0;
        float surface = 0.0;
        for (int s = 1; s <= 2 * reach; s++) {
            ivec2 q = ivec2(pixel) + s * step_px;
            if (any(lessThan(q, ivec2(0))) || q.x >= int(frame.width) || q.y >= int(frame.height)) {
                break;
            }
            Fragment g = load_fragment(uint(q.y) * frame.width + uint(q.x));
            if (taken == 0) {
                if (s > reach) {
                    break;
                }
                if (previous - g.dioptre > frame.group_tolerance_d) {
                    surface = g.dioptre;
                    taken = 1;
                    colour += g.color;
                }
                previous = g.dioptre;
            } else {
                if (taken >= reach || abs(g.dioptre - surface) > frame.group_tolerance_d) {
                    break;
                }
                colour += g.color;
                taken++;
                surface = g.dioptre;
            }
        }
        found += float(taken);
    }
    colour /= max(found, 1.0);
    return found > 0.0;
}

#endif
