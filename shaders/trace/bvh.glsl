// trace/bvh.glsl — the closest-hit and any-hit walks of the BVH that
// common/src/scene/accel.rs builds, two children a node or collapsed to four or
// eight (--accel bvh4, bvh8); compiled only into the USE_BVH variants.

#ifdef USE_BVH
const uint SPHERE_BIT = 0x80000000u;

// The traversal stack holds the far children still to visit, each entry
// uvec2(child reference, floatBitsToUint(entry t)); an any-hit walk (shadow
// rays) writes and reads only the reference (BVH_PUSH_REF, WALK_PUSH). Each API's stack takes
// the form its driver runs best (Api::bvh_stack_pairs in
// common/src/plan/requests.rs decides, as it decides the workgroup):
// - OpenGL on trees of up to 32 entries (BVH_STACK_PAIRS): two entries to a
//   uvec4. NVIDIA's OpenGL compiler reports a whole 16-byte slot for every
//   element of a local array, so two scalar arrays cost it four times the
//   memory of these pairs (what that was worth:
//   docs/findings/bvh.md#what-made-the-walk-fast; data:
//   f8d14ba:comparison/results/nvidia-h100/investigation/paired.jsonl).
// - Vulkan, and OpenGL on deeper trees: one entry a uvec2, with no test of
//   which half of a pair an entry is in. OpenGL's report then doubles, but
//   its multiprocessors do not drop; it holds 4 warps fewer, and gains from
//   the 307k-triangle teapot up
//   (docs/findings/bvh.md#the-stacks-form-in-opengl-h200).
// BVH_STACK is the built tree's depth - 1
// (common/src/shader/variant.rs): the traversal pushes at most one child per level of
// the current path, so no push is ever dropped and no slot is wasted.
//
// Experiments (--experiment, docs/experiments.md): BVH_STACK_LOCAL gives
// each walk a local stack of its own; BVH_STACK_SHARED (compute only, where
// it fits) keeps the stack in shared memory, entry-major so that a warp's
// pushes hit distinct banks.
#ifndef BVH_STACK
// Only a source compiled without the build's defines (an external compiler
// checking trace.glsl on its own) gets here: the apps always size the stack
// from the tree. A fixed stack cannot know the tree, so it drops what does
// not fit rather than write past its end.
#define BVH_STACK 64
#define BVH_STACK_FIXED 1
#endif
#if defined(BVH_STACK_SHARED)
shared uvec2 bvh_stack[BVH_STACK * WG_X * WG_Y];
#define BVH_PUSH(i, e) bvh_stack[(i) * uint(WG_X * WG_Y) + gl_LocalInvocationIndex] = (e)
#define BVH_POP(i) bvh_stack[(i) * uint(WG_X * WG_Y) + gl_LocalInvocationIndex]
#define BVH_PUSH_REF(i, c) bvh_stack[(i) * uint(WG_X * WG_Y) + gl_LocalInvocationIndex].x = (c)
#define BVH_POP_REF(i) bvh_stack[(i) * uint(WG_X * WG_Y) + gl_LocalInvocationIndex].x
#elif defined(BVH_STACK_PAIRS)
#if BVH_STACK <= 2
// Never a one-element array: Mesa 22.3's GLSL front end (llvmpipe, OpenGL)
// stores the last component written into every component of `uvec4 s[1]`, so
// one push and one pop gave (20, 20) for (10, 20) and whole objects went
// missing with --accel bvh on small trees. Two elements cost one spare slot.
#define BVH_STACK_DECLARE uvec4 stack[2]
#else
#define BVH_STACK_DECLARE uvec4 stack[(BVH_STACK + 1) / 2]
#endif
#define BVH_PUSH(i, e) if (((i) & 1u) == 0u) { stack[(i) >> 1u].xy = (e); } else { stack[(i) >> 1u].zw = (e); }
#define BVH_POP(i) (((i) & 1u) == 0u ? stack[(i) >> 1u].xy : stack[(i) >> 1u].zw)
#define BVH_PUSH_REF(i, c) if (((i) & 1u) == 0u) { stack[(i) >> 1u].x = (c); } else { stack[(i) >> 1u].z = (c); }
#define BVH_POP_REF(i) (((i) & 1u) == 0u ? stack[(i) >> 1u].x : stack[(i) >> 1u].z)
#else
// Never a one-element array either (see above).
#if BVH_STACK < 2
#define BVH_STACK_DECLARE uvec2 stack[2]
#else
#define BVH_STACK_DECLARE uvec2 stack[BVH_STACK]
#endif
#define BVH_PUSH(i, e) stack[(i)] = (e)
#define BVH_POP(i) stack[(i)]
#define BVH_PUSH_REF(i, c) stack[(i)].x = (c)
#define BVH_POP_REF(i) stack[(i)].x
#endif
#if !defined(BVH_STACK_SHARED) && !defined(BVH_STACK_LOCAL)
// One stack for both walks (closest hit and any hit), at module scope: per
// invocation like a local array, but a compiler that inlines each call of
// `traverse` cannot give each copy a stack of its own, as NVIDIA's OpenGL
// compiler did (21 slots of local memory instead of 12 for the teapot).
BVH_STACK_DECLARE;
#endif

// A child reference (gpu::layout::child_ref, which a test holds these to):
// an interior node's index, or with LEAF_BIT a leaf, its first primitive
// above LEAF_FIRST_SHIFT and its count - 1 below.
const uint LEAF_BIT = 0x80000000u;
const uint LEAF_FIRST_SHIFT = 2u;
// No child to visit: a leaf reference no tree has (its count bits say 4 and
// its first primitive is past any limit).
const uint NO_CHILD = 0xFFFFFFFFu;
// The root's reference: slot 0 of the GPU's copy is a sentinel no reference
// names (gpu::layout::child_ref::GPU_ROOT), so 0 is never an interior node.
const uint GPU_ROOT = 1u;

// Where the ray enters the box, or -1 if it misses it before t_max. Zero
// direction components are nudged (inverse_dir) so 0 * inf never makes a NaN.
float enter_box(vec3 origin, vec3 inv_dir, vec3 bmin, vec3 bmax, float t_max) {
    vec3 t0 = (bmin - origin) * inv_dir;
    vec3 t1 = (bmax - origin) * inv_dir;
    vec3 tn = min(t0, t1);
    vec3 tf = max(t0, t1);
    float enter = max(max(tn.x, tn.y), max(tn.z, 0.0));
    float leave = min(min(tf.x, tf.y), min(tf.z, t_max));
    return enter <= leave ? enter : -1.0;
}

// The smallest direction component the slab tests divide by: a zero one would
// make 0 * inf a NaN. At 2e-20 the inverse stays below 5e19, so the wide step's
// origin * inverse stays finite for any coordinate the scene checks allow
// (limits::MAX_COORDINATE, 4e18: 2e38 < 3.4e38; a test holds the two together),
// and a slab it makes of a direction this small is off by under 1e-19 of the
// distance travelled, far below f32's rounding.
const float MIN_DIR = 2.0e-20;

// How far the wide step pads its per-ray origin term, as a share of it: 2^-22,
// four times the 2^-24 that term's rounding can be off by (traverse has why).
const float ORIGIN_PAD = 2.384185791015625e-7;

// A zero component (+0 or -0) counts as positive. The sign is a select, not
// sign(dir + 1e-38): that constant is a denormal, which a driver that flushes
// denormals (Mesa's lavapipe and llvmpipe do) reads as 0, so sign(0) gave an
// inverse of 0 and every slab of that axis the width 0: the ray missed every
// box. In a frame of odd width the middle column's primary rays have a zero
// x component; through the tree the box rendered that column black
// (tests/tests/accel.rs holds it). A ray that runs exactly along a box's face
// still leaves that box at t = 0, as if it moved by MIN_DIR: on the seam of
// two of the box's floor tiles the tree takes the tile whose box it enters
// and brute force the first in order, two hits at the same point.
vec3 inverse_dir(vec3 dir) {
    vec3 d = mix(vec3(MIN_DIR), abs(dir), greaterThan(abs(dir), vec3(MIN_DIR)));
    return mix(vec3(1.0), vec3(-1.0), lessThan(dir, vec3(0.0))) / d;
}

// Tests a leaf's primitives against the ray, keeping the closest hit in h.
// True when an any-hit query (shadow rays) may stop.
bool hit_leaf(inout Hit h, vec3 origin, vec3 dir, TriRay ray, uint first, uint count, bool any_hit) {
    for (uint k = 0u; k < count; k++) {
        BvhPrim p = prim_buf.prims[first + k];
        uint prim = p.code;
        // The tests take whole structs; they read only the positions.
        if ((prim & SPHERE_BIT) != 0u) {
            uint i = prim & ~SPHERE_BIT;
            float t = hit_sphere(origin, dir, Sphere(p.a, p.b.x, 0u, 0u, 0u, 0u), 0.0, h.t);
            if (t > 0.0) {
                h.t = t;
                h.kind = 1u;
                h.index = i;
            }
        } else {
#ifdef TRIANGLE_WATERTIGHT
            Triangle tri = Triangle(p.a, 0u, p.b, 0u, p.c, 0u, vec3(0.0), 0u, vec3(0.0), 0u, vec3(0.0), 0u);
            vec3 r = hit_triangle(ray, tri, 0.0, h.t);
#else
            // p0 and the two edges (gpu::layout::GpuBvhPrim).
            vec3 r = moller_trumbore(ray, p.a, p.b, p.c, 0.0, h.t);
#endif
            if (r.x > 0.0) {
                h.t = r.x;
                h.kind = 2u;
                h.index = prim;
                h.u = r.y;
                h.v = r.z;
            }
        }
        if (any_hit && h.kind != 0u) {
            return true;
        }
    }
    return false;
}

// Room on a fixed stack (BVH_STACK_FIXED, above) for one more entry; a sized
// stack always has it, as the tree's depth sizes it.
#ifdef BVH_STACK_FIXED
#define BVH_ROOM(i) if ((i) < uint(BVH_STACK))
#else
#define BVH_ROOM(i)
#endif

// Pushes a child to visit later, entered at `tt`. A closest-hit walk keeps the
// distance, to skip the child if a hit before it turns up first. An any-hit
// walk stops at its first hit, so its bound (t_max) never shrinks: it pushes
// only a child entered before that bound, which the pop would otherwise skip,
// and only its reference, and its pop (traverse) takes every entry as it
// comes. The same children are visited in the same order; the stores and the
// pop's test are what go. The H200's 4K teapot: Vulkan -1.0 %, OpenGL -1.7 %;
// 2-3 % from 307k triangles up in both
// (docs/findings/rays-per-second.md#shadow-walks-that-push-only-what-they-visit-h200).
// (Parameters cc and tt: a macro parameter named t would rename h.t.)
#define WALK_PUSH(cc, tt)                                                                  \
    if (any_hit) {                                                                         \
        if ((tt) < h.t) {                                                                  \
            BVH_ROOM(sp) { BVH_PUSH_REF(sp, (cc)); sp += 1u; }                             \
        }                                                                                  \
    } else {                                                                               \
        BVH_ROOM(sp) { BVH_PUSH(sp, uvec2((cc), floatBitsToUint(tt))); sp += 1u; }         \
    }

// One step down from interior node `child`: on to the nearer child whose box
// the ray enters before h.t, the farther one pushed with its entry t; NO_CHILD
// if the ray enters neither. A macro, so that a walk's local stack
// (BVH_STACK_LOCAL) stays its own.
#define BVH_STEP()                                                                         \
    {                                                                                      \
        BvhNode node = bvh_buf.nodes[child];                                               \
        float tl = enter_box(origin, inv_dir, node.left_min, node.left_max, h.t);          \
        float tr = enter_box(origin, inv_dir, node.right_min, node.right_max, h.t);        \
        if (tl >= 0.0 && tr >= 0.0) {                                                      \
            bool left_first = tl <= tr;                                                    \
            child = left_first ? node.left : node.right;                                   \
            WALK_PUSH(left_first ? node.right : node.left, left_first ? tr : tl)           \
        } else if (tl >= 0.0) {                                                            \
            child = node.left;                                                             \
        } else if (tr >= 0.0) {                                                            \
            child = node.right;                                                            \
        } else {                                                                           \
            child = NO_CHILD;                                                              \
        }                                                                                  \
    }

// The wide tree (--accel bvh4, bvh8; USE_BVH_WIDE): common/src/scene/accel/wide.rs
// collapses the binary tree into nodes of four or eight children with the same
// leaves. Its step tests the four boxes of a BvhWideNode at once, sorts their
// entry distances (five compare-and-swaps), takes the nearest child next and
// pushes the others far to near, so that they pop near first. An 8-wide node
// does that for each half, keeps the nearer of the two nearest and pushes the
// other: the pops of such a node come in near-first order within each half.
// Every node pushes at most its entered children but one, which is what the
// stack is sized for. A shadow ray (any hit) only needs the nearest first
// (three compare-and-swaps): it stops at any blocker, so the order of the rest
// cannot change its answer.
//
// The slab test reads each axis's near and far planes by the sign of the ray's
// direction (near_k, far_k in traverse), so each entry and exit distance is
// already the smaller and the larger: no min and max per axis, since a
// positive inverse direction keeps min * inv - a <= max * inv - b for a >= b
// under rounding. That took Vulkan's 1080p teapot from 0.259 to 0.232 ms and
// OpenGL's from 0.319 to 0.294
// (docs/findings/bvh.md#the-tree-auto-takes; data: f8d14ba:comparison/results/nvidia-h100/investigation/octant/).
// Each distance is one fma against a per-ray origin term, padded so that no
// box is missed for its rounding (traverse has why).
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

// Pushes onto the stack, which is sized for the most entries a walk of this
// tree leaves pending (Bvh::stack_entries).
#define WIDE_PUSH(c, t) WALK_PUSH(c, t)

// One step down from wide node `child`: on to its nearest entered child, the
// others pushed; NO_CHILD (which has LEAF_BIT set) if the ray enters none. An
// empty slot's box is inside out (gpu::layout::EMPTY_SLOT_MIN), so its entry
// distance exceeds its exit in any rounding and its NO_CHILD need not be
// tested (that test cost 1-3 %). Macros, like BVH_STEP.
//
// A 4-wide node's one quad is not walked by a loop. naga writes a `for` as a
// loop with a first-time flag, and NVIDIA's OpenGL compiler kept that loop of
// one turn in its machine code, with the push of an earlier nearest child that
// only an 8-wide node's second quad can need; its Vulkan compiler removed both.
// Without the loop OpenGL's teapot frames are 6-19 % shorter and Vulkan's
// unchanged
// (docs/findings/opengl-compute.md#what-closed-the-gap).
#define WIDE_QUAD(n)                                                                   \
    {                                                                                  \
        vec4 xn = fma(bvh_wide_buf.nodes[n].bounds[near_k.x], vec4(inv_dir.x), -oi_near.xxxx); \
        vec4 xf = fma(bvh_wide_buf.nodes[n].bounds[far_k.x], vec4(inv_dir.x), -oi_far.xxxx);   \
        vec4 yn = fma(bvh_wide_buf.nodes[n].bounds[near_k.y], vec4(inv_dir.y), -oi_near.yyyy); \
        vec4 yf = fma(bvh_wide_buf.nodes[n].bounds[far_k.y], vec4(inv_dir.y), -oi_far.yyyy);   \
        vec4 zn = fma(bvh_wide_buf.nodes[n].bounds[near_k.z], vec4(inv_dir.z), -oi_near.zzzz); \
        vec4 zf = fma(bvh_wide_buf.nodes[n].bounds[far_k.z], vec4(inv_dir.z), -oi_far.zzzz);   \
        vec4 enter = max(max(xn, yn), max(zn, vec4(0.0)));                             \
        vec4 leave = min(min(xf, yf), min(zf, vec4(h.t)));                             \
        uvec4 c = bvh_wide_buf.nodes[n].child;                                         \
        float t0 = enter.x <= leave.x ? enter.x : WIDE_MISS;                           \
        float t1 = enter.y <= leave.y ? enter.y : WIDE_MISS;                           \
        float t2 = enter.z <= leave.z ? enter.z : WIDE_MISS;                           \
        float t3 = enter.w <= leave.w ? enter.w : WIDE_MISS;                           \
        uint c0 = c.x;                                                                 \
        uint c1 = c.y;                                                                 \
        uint c2 = c.z;                                                                 \
        uint c3 = c.w;                                                                 \
        if (any_hit) {                                                                 \
            wide_order(t0, c0, t1, c1);                                                \
            wide_order(t0, c0, t2, c2);                                                \
            wide_order(t0, c0, t3, c3);                                                \
        } else {                                                                       \
            wide_order(t0, c0, t1, c1);                                                \
            wide_order(t2, c2, t3, c3);                                                \
            wide_order(t0, c0, t2, c2);                                                \
            wide_order(t1, c1, t3, c3);                                                \
            wide_order(t1, c1, t2, c2);                                                \
        }                                                                              \
        if (any_hit) {                                                                 \
            WIDE_PUSH(c3, t3)                                                          \
            WIDE_PUSH(c2, t2)                                                          \
            WIDE_PUSH(c1, t1)                                                          \
        } else {                                                                       \
            if (t3 < WIDE_MISS) WIDE_PUSH(c3, t3)                                      \
            if (t2 < WIDE_MISS) WIDE_PUSH(c2, t2)                                      \
            if (t1 < WIDE_MISS) WIDE_PUSH(c1, t1)                                      \
        }                                                                              \
        if (t0 < near_t) {                                                             \
            if (near != NO_CHILD) WIDE_PUSH(near, near_t)                              \
            near = c0;                                                                 \
            near_t = t0;                                                               \
        } else if (t0 < WIDE_MISS) WIDE_PUSH(c0, t0)                                   \
    }
#if BVH_WIDE_QUADS == 1
// near and near_t are still at their start here, so no earlier nearest child
// is pushed.
#define WIDE_QUADS() WIDE_QUAD(child)
#else
// An 8-wide node keeps the loop over its two quads: written out twice, it
// made OpenGL's 8-wide walk 4-10 % faster but Vulkan's 1-5 % slower.
#define WIDE_QUADS()                                                                   \
    for (uint q = 0u; q < uint(BVH_WIDE_QUADS); q++) {                                 \
        uint n = child + q;                                                            \
        WIDE_QUAD(n)                                                                   \
    }
#endif
#define WIDE_STEP()                                                                    \
    {                                                                                  \
        uint near = NO_CHILD;                                                          \
        float near_t = WIDE_MISS;                                                      \
        WIDE_QUADS()                                                                   \
        child = near;                                                                  \
    }
#endif

// Visits the tree near child first and skips subtrees that start beyond the
// closest hit so far. With `any_hit` (shadow rays) it stops at the first hit
// before t_max and reports it with kind != 0. The loop within a loop (Aila
// and Laine 2009's "while-while") visits the same nodes and leaves in the
// same order as one loop taking a node or a leaf per turn, and was faster in
// both APIs, never slower (measured in
// docs/findings/bvh.md#what-made-the-walk-fast; data: f8d14ba:comparison/results/nvidia-h100/investigation/node-layout/).
//
// The descent goes on only through references > 0 (int(child) > 0: an
// interior node, as no reference names slot 0, the sentinel before the root;
// see GPU_ROOT). That costs no instruction: the test is one compare, as
// LEAF_BIT's was. It makes the walk end even where every read of the tree
// returns zero, which a tree never does but Mesa 22.3's llvmpipe and lavapipe
// make happen: they run a SIMD vector's lanes that are no invocation (a
// compute workgroup narrower than the vector, a fragment block's uncovered
// pixels) with storage reads of zero, and keep a loop going while such a lane
// has not left it. When 0 was the root, a zero node was the root with both
// boxes at the origin, so a ray from the origin went round it until the
// driver's budget of 65,535 loop turns per vector ran out, and every later
// loop of the real pixels was cut to one turn: the wall of hard/far-tiny-sphere
// was lost in 4x4 blocks. Now such a lane takes reference 0 for a leaf, whose
// zero primitive is degenerate and never hit, and is done after two turns.
// (A first fix took the root's step before the loops instead: it cost up to
// 5 % in OpenGL, the step's code twice; f8d14ba:comparison/results/nvidia-h100/investigation/sentinel/.) comparison/investigations/mesa-bvh/README.md has the
// driver's side and a reproducer.
//
// NODE_STEP is the step of the tree's width: the one loop walks either tree.
#ifdef USE_BVH_WIDE
#define NODE_STEP() WIDE_STEP()
#else
#define NODE_STEP() BVH_STEP()
#endif
Hit traverse(vec3 origin, vec3 dir, float t_max, bool any_hit) {
    Hit h;
    h.t = t_max;
    h.kind = 0u;
    h.index = 0u;
    h.u = 0.0;
    h.v = 0.0;
    vec3 inv_dir = inverse_dir(dir);
    TriRay ray = tri_ray(origin, dir);
#ifdef USE_BVH_WIDE
    // Each axis's near plane in BvhWideNode.bounds (min_* at 0-2, max_* at
    // 3-5) by the direction's sign, and its far plane (WIDE_STEP).
    uvec3 near_k = uvec3(inv_dir.x < 0.0 ? 3u : 0u, inv_dir.y < 0.0 ? 4u : 1u, inv_dir.z < 0.0 ? 5u : 2u);
    uvec3 far_k = uvec3(3u, 5u, 7u) - near_k;
    // Each slab distance (plane - o) * inv is one fma, plane * inv - o * inv,
    // with o * inv taken once per ray. That product's rounding is relative to
    // the origin's distance from the world's origin, not to the box, so it
    // is taken 2^-22 of itself too large for the near planes and too small for
    // the far ones: more than the 2^-24 it can be off by, so every entry
    // distance is no later and every exit no earlier than the exact one's
    // rounding. A box is never missed for it; far from the origin a few more
    // are entered (MIN_DIR keeps o * inv finite). The 1080p teapot: Vulkan
    // -4 %, OpenGL -2 %; OpenGL's compute path loses 7-8 % from a million
    // triangles up
    // (docs/findings/bvh.md#what-made-the-walk-fast; data: f8d14ba:comparison/results/nvidia-h100/investigation/fma-pad/).
    vec3 oi = origin * inv_dir;
    vec3 oi_pad = abs(oi) * ORIGIN_PAD;
    vec3 oi_near = oi + oi_pad;
    vec3 oi_far = oi - oi_pad;
#endif
#ifdef BVH_STACK_LOCAL
    BVH_STACK_DECLARE;
#endif
    uint sp = 0u;
    // The child reference being visited: first the root.
    uint child = GPU_ROOT;
    while (true) {
        // Down through interior nodes until a leaf, or until nothing is
        // entered (NO_CHILD): the warp's invocations then test their leaves
        // together instead of taking turns between node and leaf steps.
        while (int(child) > 0) {
            NODE_STEP();
        }
        if (child != NO_CHILD) {
            uint first = (child & ~LEAF_BIT) >> LEAF_FIRST_SHIFT;
            uint count = (child & ((1u << LEAF_FIRST_SHIFT) - 1u)) + 1u;
            if (hit_leaf(h, origin, dir, ray, first, count, any_hit)) {
                return h;
            }
        }
        // An any-hit walk pushed only what it will visit (WALK_PUSH).
        if (any_hit) {
            if (sp == 0u) {
                break;
            }
            sp -= 1u;
            child = BVH_POP_REF(sp);
            continue;
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
