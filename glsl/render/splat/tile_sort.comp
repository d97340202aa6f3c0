#version 460
// Sorts each tile's list by (depth, fragment index), one workgroup per tile of the band.
// Bitonic sorting network in the variant whose comparators all put the smaller key first:
// then a list of any length n behaves as if padded with +infinity up to a power of two, and
// every comparator touching the padding can be skipped. Lists up to 2048 entries sort in
// shared memory; longer ones sort in place in global memory (slower, but nothing is dropped).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define BANDS_BINDING 3
#include "band.glsl"

layout(local_size_x = 256) in;

layout(std430, binding = 0) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 1) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = 2) coherent buffer Entries { uvec2 entries[]; };

const uint SHARED_CAPACITY = 2048u;
// Up to RANK_SORT_LIMIT entries a rank sort (each key counts the keys before it) needs one
// barrier instead of the network's log² n, and keys are unique (the fragment index breaks
// ties), so ranks are a permutation. Each thread ranks RANK_KEYS consecutive keys in one pass
// over the list: on a CPU implementation (lavapipe runs a subgroup's loop only while one of its
// threads has keys, and one load serves every comparison of a step) 8 keys a thread, and
// there the keys are bucketed first (BUCKETED), so lists up to 2048 sort that way; on a GPU
// 2 keys and 512 (the network beyond).
layout(constant_id = 0) const uint RANK_KEYS = 2u;
const uint RANK_SORT_LIMIT =
    256u * RANK_KEYS > SHARED_CAPACITY ? SHARED_CAPACITY : 256u * RANK_KEYS;
const bool BUCKETED = RANK_KEYS >= 4u;
shared uvec2 keys[SHARED_CAPACITY];

// Ranks this thread's RANK_KEYS consecutive keys, keys[first …], among keys[from, to) and
// writes each to its place in the list: every key before `from` is smaller than all of them,
// every key from `to` on larger.
void rank_keys(uint first, uint n, uint from, uint to, uint base) {
    if (first >= n) {
        return;
    }
    uvec2 mine[RANK_KEYS];
    uint rank[RANK_KEYS];
    [[unroll]] for (uint k = 0u; k < RANK_KEYS; k++) {
        uint i = first + k;
        mine[k] = i < n ? keys[i] : uvec2(0u);
        rank[k] = from;
    }
    for (uint j = from; j < to; j++) {
        uvec2 other = keys[j];
        [[unroll]] for (uint k = 0u; k < RANK_KEYS; k++) {
            rank[k] += key_less(other, mine[k]) ? 1u : 0u;
        }
    }
    [[unroll]] for (uint k = 0u; k < RANK_KEYS; k++) {
        if (first + k < n) {
            entries[base + rank[k]] = mine[k];
        }
    }
}
// With four or more keys a thread (a CPU implementation) the rank sort first buckets the keys by
// depth, so that a key is compared only with the keys of nearby buckets: a bucket is a
// monotone function of the depth, so every key of an earlier bucket is smaller and every key
// of a later one larger. The order is the same; the comparisons fall from n² to about n times
// a bucket's size (a 640×360 colonnade's lists hold hundreds to a few thousand entries).
const uint BUCKETS = 128u;
shared uint bucket_count[BUCKETS];
shared uint bucket_start[BUCKETS];
shared uint depth_lo;
shared uint depth_hi;

uint bucket_of(uint depth, float scale) {
    return min(BUCKETS - 1u, uint(float(depth - depth_lo) * scale));
}

// The rank sort by buckets (BUCKETED, n ≤ RANK_SORT_LIMIT): the list is read twice from the
// entries, and keys[0, n) takes it bucket by bucket.
void bucketed_rank_sort(uint n, uint base, uint t) {
    if (t == 0u) {
        depth_lo = 0xFFFFFFFFu;
        depth_hi = 0u;
    }
    if (t < BUCKETS) {
        bucket_count[t] = 0u;
    }
    barrier();
    for (uint i = t; i < n; i += 256u) {
        uint depth = entries[base + i].x;
        atomicMin(depth_lo, depth);
        atomicMax(depth_hi, depth);
    }
    barrier();
    float scale = float(BUCKETS) / (float(depth_hi - depth_lo) + 1.0);
    for (uint i = t; i < n; i += 256u) {
        atomicAdd(bucket_count[bucket_of(entries[base + i].x, scale)], 1u);
    }
    barrier();
    if (t == 0u) {
        uint sum = 0u;
        for (uint b = 0u; b < BUCKETS; b++) {
            bucket_start[b] = sum;
            sum += bucket_count[b];
        }
    }
    barrier();
    if (t < BUCKETS) {
        // From here a cursor: the bucket's next free place.
        bucket_count[t] = bucket_start[t];
    }
    barrier();
    for (uint i = t; i < n; i += 256u) {
        uvec2 key = entries[base + i];
        keys[atomicAdd(bucket_count[bucket_of(key.x, scale)], 1u)] = key;
    }
    barrier();
    // This thread's keys are consecutive in bucket order; every key before the first one's
    // bucket is smaller than all of them, every key after the last one's bucket larger.
    uint first = RANK_KEYS * t;
    if (first >= n) {
        return;
    }
    uint last = min(first + RANK_KEYS, n) - 1u;
    uint from = bucket_start[bucket_of(keys[first].x, scale)];
    // The cursor of the last key's bucket stands at that bucket's end.
    uint to = bucket_count[bucket_of(keys[last].x, scale)];
    rank_keys(first, n, from, to, base);
}

void main() {
    load_band();
    uint tile = band.first_tile + gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
    if (tile >= band.end_tile) {
        return; // whole workgroup: no barrier is skipped by some threads only
    }
    uint n = counts[tile];
    if (n < 2u || !list_fits(offsets[tile], n)) {
        return;
    }
    uint base = offsets[tile] - band.first_entry;
    uint t = gl_LocalInvocationID.x;
    uint m = 1u;
    while (m < n) m <<= 1u;
    if (n <= RANK_SORT_LIMIT) {
        if (BUCKETED) {
            bucketed_rank_sort(n, base, t);
        } else {
            for (uint i = t; i < n; i += 256u) keys[i] = entries[base + i];
            barrier();
            rank_keys(RANK_KEYS * t, n, 0u, n, base);
        }
        return;
    }
    bool in_shared = n <= SHARED_CAPACITY;
    if (in_shared) {
        for (uint i = t; i < n; i += 256u) keys[i] = entries[base + i];
        barrier();
    }
    for (uint k = 2u; k <= m; k <<= 1u) {
        for (uint j = k >> 1u; j > 0u; j >>= 1u) {
            for (uint p = t; p < m / 2u; p += 256u) {
                uint a, b;
                if (j == k >> 1u) {
                    // First step of a merge: compare mirrored positions within the block.
                    uint block = p / j;
                    uint offset = p % j;
                    a = block * k + offset;
                    b = block * k + k - 1u - offset;
                } else {
                    uint block = p / j;
                    uint offset = p % j;
                    a = block * 2u * j + offset;
                    b = a + j;
                }
                if (b >= n) continue;
                if (in_shared) {
                    uvec2 ka = keys[a], kb = keys[b];
                    if (key_less(kb, ka)) { keys[a] = kb; keys[b] = ka; }
                } else {
                    uvec2 ka = entries[base + a], kb = entries[base + b];
                    if (key_less(kb, ka)) { entries[base + a] = kb; entries[base + b] = ka; }
                }
            }
            memoryBarrierBuffer();
            barrier();
        }
    }
    if (in_shared) {
        for (uint i = t; i < n; i += 256u) entries[base + i] = keys[i];
    }
}
