#version 460
// Exclusive prefix sum of the per-tile counts into list offsets, in three dispatches (the
// phase, `PrefixSumPush` in src/render/splat/prefix_sum.rs): 0 scans blocks of 1024 counts and
// records each block's total; 1 scans the block totals in one workgroup (any number of
// blocks); 2 adds each block's base and writes the grand total after the last offset. It needs
// no frame values, so it binds no frame block: only its own push constants.

layout(local_size_x = 256) in;

layout(push_constant) uniform PrefixSumPush {
    uint phase; // 0, 1 or 2 (above)
    uint count; // number of counts scanned
} push;

layout(std430, binding = 0) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 1) buffer Offsets { uint offsets[]; };   // count + 1 entries
layout(std430, binding = 2) buffer BlockSums { uint block_sums[]; };

shared uint partial[256];
shared uint carry;

// Exclusive scan of 1024 values, four per thread (v), across the workgroup; returns the total.
uint scan_block(uint t, inout uint v[4]) {
    uint own = 0u;
    for (int k = 0; k < 4; k++) {
        uint x = v[k];
        v[k] = own;
        own += x;
    }
    partial[t] = own;
    barrier();
    for (uint offset = 1u; offset < 256u; offset <<= 1u) {
        uint x = t >= offset ? partial[t - offset] : 0u;
        barrier();
        partial[t] += x;
        barrier();
    }
    uint before = partial[t] - own;
    uint total = partial[255];
    barrier();
    for (int k = 0; k < 4; k++) {
        v[k] += before;
    }
    return total;
}

void main() {
    uint phase = push.phase;
    uint n = push.count;
    uint t = gl_LocalInvocationID.x;
    uint v[4];
    if (phase == 0u) {
        uint base = gl_WorkGroupID.x * 1024u + t * 4u;
        for (uint k = 0u; k < 4u; k++) {
            v[k] = base + k < n ? counts[base + k] : 0u;
        }
        uint total = scan_block(t, v);
        for (uint k = 0u; k < 4u; k++) {
            if (base + k < n) offsets[base + k] = v[k];
        }
        if (t == 0u) block_sums[gl_WorkGroupID.x] = total;
    } else if (phase == 1u) {
        uint blocks = (n + 1023u) / 1024u;
        if (t == 0u) carry = 0u;
        barrier();
        for (uint start = 0u; start < blocks; start += 1024u) {
            uint base = start + t * 4u;
            for (uint k = 0u; k < 4u; k++) {
                v[k] = base + k < blocks ? block_sums[base + k] : 0u;
            }
            uint total = scan_block(t, v);
            uint before = carry;
            for (uint k = 0u; k < 4u; k++) {
                if (base + k < blocks) block_sums[base + k] = v[k] + before;
            }
            barrier();
            if (t == 0u) carry = before + total;
            barrier();
        }
        if (t == 0u) offsets[n] = carry;
    } else {
        uint base = gl_WorkGroupID.x * 1024u + t * 4u;
        uint add = block_sums[gl_WorkGroupID.x];
        for (uint k = 0u; k < 4u; k++) {
            if (base + k < n) offsets[base + k] += add;
        }
    }
}
