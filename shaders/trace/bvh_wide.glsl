// trace/bvh_wide.glsl — the closest-hit and any-hit walk of the wide BVH (four
// or eight children a node) that common/src/scene/accel/wide.rs collapses from
// the binary one; compiled only into the USE_BVH_WIDE variants, in place of
// bvh.glsl's `traverse`, whose stack, child references and leaf test it shares.

#ifdef USE_BVH_WIDE
#ifndef BVH_WIDE_QUADS
// BvhWideNodes per node: 1 for a 4-wide tree, 2 for an 8-wide one.
#define BVH_WIDE_QUADS 1
#endif

// The entry distance of a child the ray does not enter: beyond every t_max.
const float WIDE_MISS = 3.0e38;

// One step of a sorting network: the two (t, child) pairs in order of t.
void wide_order(inout float ta, inout uint ca, inout float tb, inout uint cb) {
    if (tb < ta) {
        float t = ta;
        ta = tb;
        tb = t;
        uint c = ca;
        ca = cb;
        cb = c;
    }
}

// Pushes (child, entry t) onto bvh.glsl's stack, which is sized for the most
// entries a walk of this tree leaves pending (Bvh::stack_entries).
#ifdef BVH_STACK_FIXED
#define WIDE_PUSH(c, t) if (sp < uint(BVH_STACK)) { BVH_PUSH(sp, uvec2((c), floatBitsToUint(t))); sp += 1u; }
#else
#define WIDE_PUSH(c, t) { BVH_PUSH(sp, uvec2((c), floatBitsToUint(t))); sp += 1u; }
#endif

// One step down from wide node `child`: on to its nearest entered child, the
// others pushed; NO_CHILD (which has LEAF_BIT set) if the ray enters none. An
// empty slot's box is never entered, and its NO_CHILD is checked as well, so
// that no driver's handling of infinity matters. A macro, like bvh.glsl's
// BVH_STEP.
#define WIDE_STEP()                                                                    \
    {                                                                                  \
        uint near = NO_CHILD;                                                          \
        float near_t = WIDE_MISS;                                                      \
        for (uint q = 0u; q < uint(BVH_WIDE_QUADS); q++) {                             \
            BvhWideNode node = bvh_wide_buf.nodes[child + q];                          \
            vec4 x0 = (node.min_x - origin.x) * inv_dir.x;                             \
            vec4 x1 = (node.max_x - origin.x) * inv_dir.x;                             \
            vec4 y0 = (node.min_y - origin.y) * inv_dir.y;                             \
            vec4 y1 = (node.max_y - origin.y) * inv_dir.y;                             \
            vec4 z0 = (node.min_z - origin.z) * inv_dir.z;                             \
            vec4 z1 = (node.max_z - origin.z) * inv_dir.z;                             \
            vec4 enter = max(max(min(x0, x1), min(y0, y1)), max(min(z0, z1), vec4(0.0))); \
            vec4 leave = min(min(max(x0, x1), max(y0, y1)), min(max(z0, z1), vec4(h.t))); \
            uvec4 c = node.child;                                                      \
            float t0 = (enter.x <= leave.x && c.x != NO_CHILD) ? enter.x : WIDE_MISS;  \
            float t1 = (enter.y <= leave.y && c.y != NO_CHILD) ? enter.y : WIDE_MISS;  \
            float t2 = (enter.z <= leave.z && c.z != NO_CHILD) ? enter.z : WIDE_MISS;  \
            float t3 = (enter.w <= leave.w && c.w != NO_CHILD) ? enter.w : WIDE_MISS;  \
            uint c0 = c.x;                                                             \
            uint c1 = c.y;                                                             \
            uint c2 = c.z;                                                             \
            uint c3 = c.w;                                                             \
            wide_order(t0, c0, t1, c1);                                                \
            wide_order(t2, c2, t3, c3);                                                \
            wide_order(t0, c0, t2, c2);                                                \
            wide_order(t1, c1, t3, c3);                                                \
            wide_order(t1, c1, t2, c2);                                                \
            if (t3 < WIDE_MISS) WIDE_PUSH(c3, t3)                                      \
            if (t2 < WIDE_MISS) WIDE_PUSH(c2, t2)                                      \
            if (t1 < WIDE_MISS) WIDE_PUSH(c1, t1)                                      \
            if (t0 < near_t) {                                                         \
                if (near != NO_CHILD) WIDE_PUSH(near, near_t)                          \
                near = c0;                                                             \
                near_t = t0;                                                           \
            } else if (t0 < WIDE_MISS) WIDE_PUSH(c0, t0)                               \
        }                                                                              \
        child = near;                                                                  \
    }

// bvh.glsl's walk for a wide node: the four boxes of a BvhWideNode are tested
// at once, their entry distances sorted (five compare-and-swaps), the nearest
// child taken next and the others pushed far to near, so that they pop near
// first. An 8-wide node does that for each half, keeps the nearer of the two
// nearest and pushes the other: the pops of such a node come in near-first
// order within each half. Every node pushes at most its entered children but
// one, which is what the stack is sized for.
Hit traverse(vec3 origin, vec3 dir, float t_max, bool any_hit) {
    Hit h;
    h.t = t_max;
    h.kind = 0u;
    h.index = 0u;
    h.u = 0.0;
    h.v = 0.0;
    vec3 inv_dir = inverse_dir(dir);
    TriRay ray = tri_ray(origin, dir);
#ifdef BVH_STACK_LOCAL
    BVH_STACK_DECLARE;
#endif
    uint sp = 0u;
    // The descent goes on only through references > 0, as in bvh.glsl's
    // `traverse` (why: there).
    uint child = GPU_ROOT;
    while (true) {
        while (int(child) > 0) {
            WIDE_STEP();
        }
        if (child != NO_CHILD) {
            uint first = (child & ~LEAF_BIT) >> LEAF_FIRST_SHIFT;
            uint count = (child & ((1u << LEAF_FIRST_SHIFT) - 1u)) + 1u;
            if (hit_leaf(h, origin, dir, ray, first, count, any_hit)) {
                return h;
            }
        }
        // Pop the nearest pending subtree that can still hold a closer hit.
        bool found = false;
        while (sp > 0u && !found) {
            sp -= 1u;
            uvec2 entry = BVH_POP(sp);
            if (uintBitsToFloat(entry.y) < h.t) {
                child = entry.x;
                found = true;
            }
        }
        if (!found) {
            break;
        }
    }
    return h;
}
#endif
