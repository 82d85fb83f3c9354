// trace.glsl — the one Whitted-style tracer, assembled from shaders/trace/*.glsl (edit those; a test regenerates this file with TWINRAY_UPDATE_DOCS=1).
// trace/inputs.glsl — what the tracer reads: the compile-time switches, the
// structs that common/src/gpu/layout.rs mirrors (a test checks naga's layout against
// the Rust one), and every binding. The first part of trace.glsl's tracer.

#ifndef STACK_SIZE
#define STACK_SIZE 17
#endif

// The specialization-constant alternative (`--specialize`, common/src/shader/variant.rs):
// every feature is compiled in and each becomes a constant_id override, which
// naga's process_overrides fixes per scene before it writes SPIR-V or GLSL.
// SPEC(x) guards a feature's code with an `if` on its constant; without
// SPECIALIZE it expands to nothing and the #ifdef alone decides.
#ifdef SPECIALIZE
layout(constant_id = 0) const bool SPEC_SPHERES = true;
layout(constant_id = 1) const bool SPEC_TRIANGLES = true;
layout(constant_id = 2) const bool SPEC_MIRROR = true;
layout(constant_id = 3) const bool SPEC_GLASS = true;
#define HAS_SPHERES 1
#define HAS_TRIANGLES 1
#define HAS_MIRROR 1
#define HAS_GLASS 1
#define SPEC(feature) if (feature)
#else
#define SPEC(feature)
#endif

struct Material {
    vec3 ambient;
    float reflectivity;
    vec3 diffuse;
    float transparency;
    vec3 specular;
    float shininess;
    float ior;
    uint pad0;
    uint pad1;
    uint pad2;
};

struct Sphere {
    vec3 center;
    float radius;
    uint material;
    uint pad0;
    uint pad1;
    uint pad2;
};

// Vertices and per-vertex normals; the material index rides in p0's spare slot.
struct Triangle {
    vec3 p0;
    uint material;
    vec3 p1;
    uint pad0;
    vec3 p2;
    uint pad1;
    vec3 n0;
    uint pad2;
    vec3 n1;
    uint pad3;
    vec3 n2;
    uint pad4;
};

struct Light {
    vec3 position;
    float pad0;
    vec3 color;
    float pad1;
};

// The camera is an eye plus the centre of the top-left pixel and per-pixel steps:
// the y step points down the image, so both APIs produce the same upright image.
layout(std140, set = 0, binding = 0) uniform Frame {
    vec3 eye;
    float min_weight;
    vec3 top_left;  // relative to the eye (see common/src/scene/camera.rs)
    float epsilon;
    vec3 step_x;
    uint max_depth;
    vec3 step_y;
    uint sphere_count;    // read only where SPHERE_COUNT is not given (see below)
    vec3 background;
    uint triangle_count;
    uint light_count;
    uint width;   // image size in pixels: the compute entry point's bounds check
    uint height;
    uint pad;
} frame;

// The counts as a storage buffer: read at run time, yet no driver inlines
// them into a new shader the way lavapipe does with uniform values.
layout(std430, set = 0, binding = 9) readonly buffer Counts {
    uint spheres;
    uint triangles;
    uint lights;
} count_buf;

// Every variant an app runs bakes the counts in (shader.rs, Variant::chosen)
// or reads them from Counts; only the scene-independent generic variant of the
// tests reads them from the uniform.
#if defined(COUNTS_FROM_STORAGE)
#define SPHERE_COUNT count_buf.spheres
#define TRIANGLE_COUNT count_buf.triangles
#define LIGHT_COUNT count_buf.lights
#elif !defined(SPHERE_COUNT)
#define SPHERE_COUNT frame.sphere_count
#define TRIANGLE_COUNT frame.triangle_count
#define LIGHT_COUNT frame.light_count
#endif

layout(std430, set = 0, binding = 1) readonly buffer Spheres {
    Sphere spheres[];
} sphere_buf;

layout(std430, set = 0, binding = 2) readonly buffer Triangles {
    Triangle triangles[];
} triangle_buf;

layout(std430, set = 0, binding = 3) readonly buffer Materials {
    Material materials[];
} material_buf;

layout(std430, set = 0, binding = 4) readonly buffer Lights {
    Light lights[];
} light_buf;

// The BVH (common/src/scene/accel.rs): interior nodes, each holding both of
// its children's boxes (one 64-byte read per step), node 0 the root. A child
// is a reference: an interior node's index, or with the top bit set a leaf,
// prims[first .. first + count] (bvh.glsl decodes it).
// Bound always; read only by the USE_BVH variant.
struct BvhNode {
    vec3 left_min;
    uint left;
    vec3 left_max;
    uint pad0;
    vec3 right_min;
    uint right;
    vec3 right_max;
    uint pad1;
};

layout(std430, set = 0, binding = 6) readonly buffer BvhNodes {
    BvhNode nodes[];
} bvh_buf;

// The leaves' primitives in leaf order, each with only what its test reads
// (a triangle's corners, or a sphere's centre and radius in b.x), so a leaf
// is one contiguous read. `code` is a triangle index, or a sphere index with
// the top bit set: the hit keeps it for shading.
struct BvhPrim {
    vec3 a;
    uint code;
    vec3 b;
    uint pad0;
    vec3 c;
    uint pad1;
};

layout(std430, set = 0, binding = 7) readonly buffer BvhPrims {
    BvhPrim prims[];
} prim_buf;

const float T_MAX = 1.0e30;

#ifdef COUNT_RAYS
// The counting variant (COUNT_RAYS: one untimed frame, never the timed shader)
// counts each pixel's rays by kind in `rays_traced` and stores them in the
// pixel's own slot; the apps add the slots up. A slot per pixel needs no
// atomics, which naga's GLSL front end does not parse.
struct RayCount {
    uint primary;
    uint shadow;
    uint mirror;           // reflected from a surface that is not glass
    uint glass_reflected;
    uint glass_refracted;
};

layout(std430, set = 0, binding = 10) buffer RayCounts {
    RayCount pixels[];
} ray_count_buf;

RayCount rays_traced;
#endif

// trace/intersect.glsl — where one ray meets one sphere or one triangle, and
// the per-primitive steps that the brute-force loops and the BVH leaves share.

// Ray-sphere tests. `dir` is unit length; both return the nearest t in
// (t_min, t_max) or -1. Conditions are written so that NaN fails them.
float hit_sphere(vec3 origin, vec3 dir, Sphere s, float t_min, float t_max) {
    vec3 f = origin - s.center;
    float r2 = s.radius * s.radius;
#ifdef SPHERE_QUADRATIC
    // The textbook quadratic a t^2 + b t + c = 0. b^2 - 4ac cancels when the
    // sphere is small against its distance, and -b + sqrt(disc) cancels for the
    // near root.
    float a = dot(dir, dir);
    float b = 2.0 * dot(f, dir);
    float c = dot(f, f) - r2;
    float disc = b * b - 4.0 * a * c;
    if (!(disc >= 0.0)) {
        return -1.0;
    }
    float sq = sqrt(disc);
    float lo = (-b - sq) / (2.0 * a);
    float hi = (-b + sq) / (2.0 * a);
#else
    // Stable form (Haines et al., Ray Tracing Gems ch. 7): the discriminant is
    // formed from the distance of the centre to the ray, and the two roots as c/q
    // and q, which avoids cancellation for small or far spheres.
    float b = dot(f, dir);
    vec3 l = f - b * dir;
    float disc = r2 - dot(l, l);
    if (!(disc >= 0.0)) {
        return -1.0;
    }
    float c = dot(f, f) - r2;
    float q = -b - (b >= 0.0 ? 1.0 : -1.0) * sqrt(disc);
    float t0 = c / q;
    float t1 = q;
    float lo = min(t0, t1);
    float hi = max(t0, t1);
#endif
    if (lo > t_min && lo < t_max) {
        return lo;
    }
    if (hi > t_min && hi < t_max) {
        return hi;
    }
    return -1.0;
}

// A ray as the triangle test wants it. The watertight test permutes and shears
// space once per ray (Woop, Benthin, Wald 2013): kz is the dominant axis of the
// direction, kx and ky the others (swapped to keep the winding), s the shear.
struct TriRay {
    vec3 o;
    vec3 d;
    uvec3 k;
    vec3 s;
};

TriRay tri_ray(vec3 o, vec3 d) {
    TriRay r;
    r.o = o;
    r.d = d;
    r.k = uvec3(0u, 1u, 2u);
    r.s = vec3(0.0);
#ifdef TRIANGLE_WATERTIGHT
    vec3 ad = abs(d);
    uint kz = ad.x > ad.y ? (ad.x > ad.z ? 0u : 2u) : (ad.y > ad.z ? 1u : 2u);
    uint kx = kz == 2u ? 0u : kz + 1u;
    uint ky = kx == 2u ? 0u : kx + 1u;
    if (d[kz] < 0.0) {
        uint tmp = kx;
        kx = ky;
        ky = tmp;
    }
    r.k = uvec3(kx, ky, kz);
    r.s = vec3(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
#endif
    return r;
}

// A triangle whose edges are parallel in f32 has no normal (normalize(0) is
// undefined), yet rounding can still let a ray through a collinear triangle's
// line pass either test. Checked only for candidate hits, so it costs little.
bool is_degenerate(Triangle tri) {
    vec3 c = cross(tri.p1 - tri.p0, tri.p2 - tri.p0);
    return c.x == 0.0 && c.y == 0.0 && c.z == 0.0;
}

// Returns (t, u, v) with u, v the weights of p1 and p2, or t = -1 for a miss.
// Conditions are written so that NaN fails them: a degenerate triangle is never hit.
vec3 hit_triangle(TriRay r, Triangle tri, float t_min, float t_max) {
    vec3 miss = vec3(-1.0, 0.0, 0.0);
#ifdef TRIANGLE_WATERTIGHT
    // Vertices relative to the origin, in the sheared frame where the ray is +z.
    // Each vertex is transformed alone, so two triangles sharing an edge compute
    // the same 2D edge function with opposite sign: no ray slips between them.
    vec3 a = tri.p0 - r.o;
    vec3 b = tri.p1 - r.o;
    vec3 c = tri.p2 - r.o;
    float ax = a[r.k.x] - r.s.x * a[r.k.z];
    float ay = a[r.k.y] - r.s.y * a[r.k.z];
    float bx = b[r.k.x] - r.s.x * b[r.k.z];
    float by = b[r.k.y] - r.s.y * b[r.k.z];
    float cx = c[r.k.x] - r.s.x * c[r.k.z];
    float cy = c[r.k.y] - r.s.y * c[r.k.z];
    float eu = cx * by - cy * bx;
    float ev = ax * cy - ay * cx;
    float ew = bx * ay - by * ax;
    // Edges exactly through the ray count for both neighbours (the paper's f64
    // re-test of zero edge functions is left out: GLSL here has no f64).
    if ((eu < 0.0 || ev < 0.0 || ew < 0.0) && (eu > 0.0 || ev > 0.0 || ew > 0.0)) {
        return miss;
    }
    float det = eu + ev + ew;
    if (det == 0.0) {
        return miss;
    }
    float tz = eu * (r.s.z * a[r.k.z]) + ev * (r.s.z * b[r.k.z]) + ew * (r.s.z * c[r.k.z]);
    float inv = 1.0 / det;
    float t = tz * inv;
    // Computed on every call, as naga always did for the call right of `||`
    // this once was (the product's timings include it; testing it only
    // inside the branch was slower on the H100's brute-force teapot, along
    // with early exits in the shadow test).
    bool degenerate = is_degenerate(tri);
    if (!(t > t_min && t < t_max) || degenerate) {
        return miss;
    }
    return vec3(t, ev * inv, ew * inv);
#else
    // Moller-Trumbore 1997.
    vec3 e1 = tri.p1 - tri.p0;
    vec3 e2 = tri.p2 - tri.p0;
    vec3 pv = cross(r.d, e2);
    float det = dot(e1, pv);
    if (det == 0.0) {
        return miss;
    }
    float inv = 1.0 / det;
    vec3 tv = r.o - tri.p0;
    float u = dot(tv, pv) * inv;
    if (!(u >= 0.0 && u <= 1.0)) {
        return miss;
    }
    vec3 qv = cross(tv, e1);
    float v = dot(r.d, qv) * inv;
    if (!(v >= 0.0 && u + v <= 1.0)) {
        return miss;
    }
    float t = dot(e2, qv) * inv;
    // Computed on every call, as naga always did for the call right of `||`
    // this once was (the product's timings include it; testing it only
    // inside the branch was slower on the H100's brute-force teapot, along
    // with early exits in the shadow test).
    bool degenerate = is_degenerate(tri);
    if (!(t > t_min && t < t_max) || degenerate) {
        return miss;
    }
    return vec3(t, u, v);
#endif
}

struct Hit {
    float t;
    uint kind;  // 0 none, 1 sphere, 2 triangle
    uint index;
    float u;
    float v;
};

// Mesa's software drivers (llvmpipe and lavapipe, 22.3) give each invocation one
// budget of 65,535 loop iterations for all its loops together and silently leave
// a loop once it is spent. The brute-force teapot (19,200 triangles, 3 shadow
// rays) needs 76,800, so the primitive loops visit four primitives per iteration.
// The order of the tests is unchanged, so the result equals the plain loop's.
#define PRIMS_PER_ITERATION 4u

void closest_sphere(inout Hit h, vec3 origin, vec3 dir, uint i) {
    if (i < SPHERE_COUNT) {
        float t = hit_sphere(origin, dir, sphere_buf.spheres[i], 0.0, h.t);
        if (t > 0.0) {
            h.t = t;
            h.kind = 1u;
            h.index = i;
        }
    }
}

void closest_triangle(inout Hit h, TriRay ray, uint i) {
    if (i < TRIANGLE_COUNT) {
        vec3 r = hit_triangle(ray, triangle_buf.triangles[i], 0.0, h.t);
        if (r.x > 0.0) {
            h.t = r.x;
            h.kind = 2u;
            h.index = i;
            h.u = r.y;
            h.v = r.z;
        }
    }
}

// trace/bvh.glsl — the closest-hit and any-hit walks of the BVH that
// common/src/scene/accel.rs builds; compiled only into the USE_BVH variants.

#ifdef USE_BVH
const uint SPHERE_BIT = 0x80000000u;

// The traversal stack holds the far children still to visit, each entry
// uvec2(child reference, floatBitsToUint(entry t)), two entries to a uvec4: NVIDIA's
// OpenGL compiler gives every element of a local array a whole 16-byte slot,
// so two scalar arrays cost it four times the memory of these pairs (on an
// H100 its teapot BVH tracer went from 259 slots to 21, and from 6.2 to
// 0.54 ms on the compute path). BVH_STACK is the built tree's depth - 1
// (common/src/shader/variant.rs): the traversal pushes at most one child per level of
// the current path, so no push is ever dropped and no slot is wasted.
//
// Experiments (--experiment, common/src/cli.rs): BVH_STACK_UNPAIRED keeps
// one uvec2 per element; BVH_STACK_LOCAL gives each walk a local stack of its
// own; BVH_STACK_SHARED (compute only, where it fits) keeps the stack in
// shared memory, entry-major so that a warp's pushes hit distinct banks.
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
#elif defined(BVH_STACK_UNPAIRED)
#if BVH_STACK < 2
// At least two elements, for the reason given below.
#define BVH_STACK_DECLARE uvec2 stack[2]
#else
#define BVH_STACK_DECLARE uvec2 stack[BVH_STACK]
#endif
#define BVH_PUSH(i, e) stack[i] = (e)
#define BVH_POP(i) stack[i]
#else
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

// Where the ray enters the box, or -1 if it misses it before t_max. Zero
// direction components are nudged so 0 * inf never makes a NaN.
float enter_box(vec3 origin, vec3 inv_dir, vec3 bmin, vec3 bmax, float t_max) {
    vec3 t0 = (bmin - origin) * inv_dir;
    vec3 t1 = (bmax - origin) * inv_dir;
    vec3 tn = min(t0, t1);
    vec3 tf = max(t0, t1);
    float enter = max(max(tn.x, tn.y), max(tn.z, 0.0));
    float leave = min(min(tf.x, tf.y), min(tf.z, t_max));
    return enter <= leave ? enter : -1.0;
}

vec3 inverse_dir(vec3 dir) {
    vec3 d = mix(vec3(1.0e-30), abs(dir), greaterThan(abs(dir), vec3(1.0e-30)));
    return sign(dir + vec3(1.0e-38)) / d;
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
            Triangle tri = Triangle(p.a, 0u, p.b, 0u, p.c, 0u, vec3(0.0), 0u, vec3(0.0), 0u, vec3(0.0), 0u);
            vec3 r = hit_triangle(ray, tri, 0.0, h.t);
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

// Visits the tree near child first and skips subtrees that start beyond the
// closest hit so far. With `any_hit` (shadow rays) it stops at the first hit
// before t_max and reports it with kind != 0. The loop within a loop (Aila
// and Laine 2009's "while-while") visits the same nodes and leaves in the
// same order as one loop taking a node or a leaf per turn, and was up to 18 %
// faster on an H100, in both APIs and never slower (comparison/results/
// nvidia-h100/FINDINGS.md, "The node layout").
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
    // The child reference being visited; the root is interior node 0.
    uint child = 0u;
    while (true) {
        // Down through interior nodes until a leaf, or until nothing is
        // entered (NO_CHILD): the warp's invocations then test their leaves
        // together instead of taking turns between node and leaf steps.
        while ((child & LEAF_BIT) == 0u) {
            BvhNode node = bvh_buf.nodes[child];
            float tl = enter_box(origin, inv_dir, node.left_min, node.left_max, h.t);
            float tr = enter_box(origin, inv_dir, node.right_min, node.right_max, h.t);
            if (tl >= 0.0 && tr >= 0.0) {
                bool left_first = tl <= tr;
                child = left_first ? node.left : node.right;
                // sp < BVH_STACK here: the stack is as deep as the tree.
#ifdef BVH_STACK_FIXED
                if (sp < uint(BVH_STACK))
#endif
                {
                    BVH_PUSH(sp, uvec2(left_first ? node.right : node.left, floatBitsToUint(left_first ? tr : tl)));
                    sp += 1u;
                }
            } else if (tl >= 0.0) {
                child = node.left;
            } else if (tr >= 0.0) {
                child = node.right;
            } else {
                child = NO_CHILD;
            }
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
// trace/hit.glsl — the two questions the ray loop asks (the closest hit, and is
// anything in the way of a light), answered by testing every primitive or,
// where the variant has one, through the BVH.

Hit closest_hit_brute(vec3 origin, vec3 dir) {
    Hit h;
    h.t = T_MAX;
    h.kind = 0u;
    h.index = 0u;
    h.u = 0.0;
    h.v = 0.0;
#ifdef HAS_SPHERES
    SPEC(SPEC_SPHERES) {
        for (uint i = 0u; i < SPHERE_COUNT; i += PRIMS_PER_ITERATION) {
            closest_sphere(h, origin, dir, i);
            closest_sphere(h, origin, dir, i + 1u);
            closest_sphere(h, origin, dir, i + 2u);
            closest_sphere(h, origin, dir, i + 3u);
        }
    }
#endif
#ifdef HAS_TRIANGLES
    SPEC(SPEC_TRIANGLES) {
        TriRay ray = tri_ray(origin, dir);
        for (uint i = 0u; i < TRIANGLE_COUNT; i += PRIMS_PER_ITERATION) {
            closest_triangle(h, ray, i);
            closest_triangle(h, ray, i + 1u);
            closest_triangle(h, ray, i + 2u);
            closest_triangle(h, ray, i + 3u);
        }
    }
#endif
    return h;
}

// naga's GLSL front end does not short-circuit && and ||: whatever stands
// right of them is evaluated every time (gfx-rs/wgpu#4394), so the code says
// so. The four tests of a group all run and are or-ed, which is what the GPU
// runs fastest (early exits after each cost the brute-force sphere list 6-10 %
// on an H100); the index is clamped so that the tests past the last primitive
// read a real one, and `i < COUNT` then discards them.
bool sphere_blocks(vec3 origin, vec3 dir, float dist, uint i) {
    bool blocks = hit_sphere(origin, dir, sphere_buf.spheres[min(i, SPHERE_COUNT - 1u)], 0.0, dist) > 0.0;
    return i < SPHERE_COUNT && blocks;
}

bool triangle_blocks(TriRay ray, float dist, uint i) {
    bool blocks = hit_triangle(ray, triangle_buf.triangles[min(i, TRIANGLE_COUNT - 1u)], 0.0, dist).x > 0.0;
    return i < TRIANGLE_COUNT && blocks;
}

// Shadow rays need any hit before the light, not the closest one.
bool occluded_brute(vec3 origin, vec3 dir, float dist) {
#ifdef HAS_SPHERES
    SPEC(SPEC_SPHERES) {
        for (uint i = 0u; i < SPHERE_COUNT; i += PRIMS_PER_ITERATION) {
            bool b0 = sphere_blocks(origin, dir, dist, i);
            bool b1 = sphere_blocks(origin, dir, dist, i + 1u);
            bool b2 = sphere_blocks(origin, dir, dist, i + 2u);
            bool b3 = sphere_blocks(origin, dir, dist, i + 3u);
            if (b0 || b1 || b2 || b3) {
                return true;
            }
        }
    }
#endif
#ifdef HAS_TRIANGLES
    SPEC(SPEC_TRIANGLES) {
        TriRay ray = tri_ray(origin, dir);
        for (uint i = 0u; i < TRIANGLE_COUNT; i += PRIMS_PER_ITERATION) {
            bool b0 = triangle_blocks(ray, dist, i);
            bool b1 = triangle_blocks(ray, dist, i + 1u);
            bool b2 = triangle_blocks(ray, dist, i + 2u);
            bool b3 = triangle_blocks(ray, dist, i + 3u);
            if (b0 || b1 || b2 || b3) {
                return true;
            }
        }
    }
#endif
    return false;
}

// The closest hit and the shadow test, through the BVH where the scene's
// variant uses one, else by testing every primitive.
Hit closest_hit(vec3 origin, vec3 dir) {
#ifdef USE_BVH
    return traverse(origin, dir, T_MAX, false);
#else
    return closest_hit_brute(origin, dir);
#endif
}

bool occluded(vec3 origin, vec3 dir, float dist) {
#ifdef COUNT_RAYS
    rays_traced.shadow += 1u;
#endif
#ifdef USE_BVH
    return traverse(origin, dir, dist, true).kind != 0u;
#else
    return occluded_brute(origin, dir, dist);
#endif
}

// trace/secondary.glsl — where a secondary ray starts, and how much of it glass
// reflects.

// Where a secondary ray starts: p is the hit point, n the geometric normal on
// the side the new ray leaves from, dir the new ray's direction. The computed p
// lies off the surface by its rounding error (about an ULP of its largest
// coordinate), so a start too close re-hits the surface (acne) and one too far
// misses nearby occluders (detached shadows, light leaks).
float max_abs(vec3 v) {
    return max(abs(v.x), max(abs(v.y), abs(v.z)));
}

#ifdef OFFSET_ULP
// Wachter & Binder, Ray Tracing Gems ch. 6: move each coordinate by 256 ULPs per
// unit of normal in integer space; near the origin, where ULPs get tiny, by a
// fixed 1/65536 instead.
const float ULP_ORIGIN = 1.0 / 32.0;
const float ULP_FLOAT_SCALE = 1.0 / 65536.0;
const float ULP_INT_SCALE = 256.0;

float ulp_offset_1(float p, float n) {
    int of = int(ULP_INT_SCALE * n);
    float moved = intBitsToFloat(floatBitsToInt(p) + (p < 0.0 ? -of : of));
    return abs(p) < ULP_ORIGIN ? p + ULP_FLOAT_SCALE * n : moved;
}
#endif

// `scale` is the largest coordinate of the ray origin the hit was found from,
// and of the vertices for a triangle; only OFFSET_SCALE_AWARE uses it. (Not the
// sphere's |centre| + radius: the stable test re-tests a radius-1e6 ground from
// near its surface cleanly, and that scale would lift shadow rays by a unit.) 2^-22 is 2 f32 ULPs at the top of a binade
// and 4 at its bottom: 2^-23 let acne through in scenes/hard/tiny-1e-4, 2^-21
// detached the shadows of scenes/hard/far-1e6 (twinray accuracy measures both).
const float SCALE_AWARE_REL = 1.0 / 4194304.0;

vec3 spawn_point(vec3 p, vec3 n, vec3 dir, float scale) {
#if defined(OFFSET_RAY)
    return p + frame.epsilon * dir;
#elif defined(OFFSET_NORMAL)
    return p + frame.epsilon * n;
#elif defined(OFFSET_ULP)
    return vec3(ulp_offset_1(p.x, n.x), ulp_offset_1(p.y, n.y), ulp_offset_1(p.z, n.z));
#elif defined(OFFSET_SCALE_AWARE)
    // The rounding error of p = o + t d is about an ULP of the largest
    // coordinate of o and p; move a few of those. No absolute floor, so tiny
    // scenes near the origin keep offsets to scale.
    return p + n * (SCALE_AWARE_REL * max(scale, max_abs(p)));
#else
    // OFFSET_NORMAL_SCALED: epsilon relative to the largest coordinate, at least absolute.
    // (Its own magnitude, not the parameter: GLSL forbids redeclaring `scale`.)
    float magnitude = max(1.0, max_abs(p));
    return p + n * (frame.epsilon * magnitude);
#endif
}

const float SHADOW_REACH = 0.9999;

// Unpolarised Fresnel reflectance of a dielectric boundary.
float fresnel(float cos_i, float cos_t, float eta) {
    float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

// trace/loop.glsl — the ray loop with its Phong shading, shadow, mirror and
// glass rays; the last part of the tracer.
//
// The tracer is written in parts that follow the walkthrough's vocabulary, in
// reading order:
//   trace/inputs.glsl     switches, structs and bindings
//   trace/intersect.glsl  ray-sphere and ray-triangle tests
//   trace/bvh.glsl        the BVH traversal
//   trace/hit.glsl        closest hit and shadow test, brute force or BVH
//   trace/secondary.glsl  where secondary rays start; Fresnel
//   trace/loop.glsl       the ray loop
// naga has no #include, so shaders/trace.glsl is these parts put together, in
// one place (TRACE_PARTS in common/src/shader/build.rs): the single tracer that
// every entry point (trace.frag, trace.comp) and any external compiler takes.
// A test keeps it equal to the parts; after editing one, regenerate it with
// TWINRAY_UPDATE_DOCS=1 cargo test --release -p twinray-common --test shader_output
//
// Features a scene lacks are compiled out through defines chosen in
// common's shader module: HAS_SPHERES, HAS_TRIANGLES, HAS_MIRROR, HAS_GLASS,
// and STACK_SIZE (the ray stack: max_depth + 1 with glass, else 1).
//
// The primitive and light counts are defines too (SPHERE_COUNT, TRIANGLE_COUNT,
// LIGHT_COUNT): they bound the loops, and a loop bound read from
// a uniform made Mesa's lavapipe compile and keep a new copy of the shader at
// every draw (about 3 MB a frame). The scene's variant knows them anyway.
//
// Numerical choices are defines too (common/src/scene/numerics.rs), one of each:
//   OFFSET_RAY | OFFSET_NORMAL | OFFSET_NORMAL_SCALED | OFFSET_ULP | OFFSET_SCALE_AWARE  (secondary-ray origin)
//   TRIANGLE_MOLLER_TRUMBORE | TRIANGLE_WATERTIGHT                    (ray-triangle test)
//   SPHERE_QUADRATIC | SPHERE_STABLE                                  (ray-sphere test)
// With none given, the shader falls back to normal-scaled / Moller-Trumbore / stable.
//
// The CPU reference (common/src/reference/) follows these files step by step
// in f64; change both together.

// The ray stack: each entry is two vec4s, (origin, weight) and (direction,
// depth). NVIDIA's OpenGL compiler gives every element of a local array a
// 16-byte slot of its own, so an entry kept as a vec3, a vec3, a float and a
// uint took four slots where these take two; and NVIDIA's OpenGL runs a
// compute shader on fewer multiprocessors the more local memory each
// invocation needs (comparison/results/nvidia-h100/FINDINGS.md, "Local memory
// and OpenGL's multiprocessors"). RAY_STACK_SPLIT (--experiment
// split-ray-stack) puts back the four arrays. The depth is a small integer,
// exact as a float.
#ifdef RAY_STACK_SPLIT
#define RAY_STACK_DECLARE vec3 st_origin[STACK_SIZE]; vec3 st_dir[STACK_SIZE]; float st_weight[STACK_SIZE]; uint st_depth[STACK_SIZE]
#define RAY_PUSH(i, o, d, w, depth) st_origin[i] = (o); st_dir[i] = (d); st_weight[i] = (w); st_depth[i] = (depth)
#define RAY_POP(i) o = st_origin[i]; d = st_dir[i]; w = st_weight[i]; depth = st_depth[i]
#else
#define RAY_STACK_DECLARE vec4 st_origin_weight[STACK_SIZE]; vec4 st_dir_depth[STACK_SIZE]
#define RAY_PUSH(i, o, d, w, depth) st_origin_weight[i] = vec4((o), (w)); st_dir_depth[i] = vec4((d), float(depth))
#define RAY_POP(i) o = st_origin_weight[i].xyz; w = st_origin_weight[i].w; d = st_dir_depth[i].xyz; depth = uint(st_dir_depth[i].w)
#endif

vec3 trace(vec3 origin, vec3 dir) {
    RAY_STACK_DECLARE;
#ifdef HAS_GLASS
    // Glass pushes two rays per hit: the stack's size bounds the depth.
    uint max_depth = min(frame.max_depth, uint(STACK_SIZE - 1));
#else
    // A mirror pushes one ray after popping one: one slot serves any depth.
    uint max_depth = frame.max_depth;
#endif

    vec3 color = vec3(0.0);
    int sp = 0;
    RAY_PUSH(0, origin, dir, 1.0, 0u);
    sp = 1;

    while (sp > 0) {
        sp -= 1;
        vec3 o;
        vec3 d;
        float w;
        uint depth;
        RAY_POP(sp);

        // The shading stays written out here rather than in functions: naga's
        // output for a struct returned by value and `out` parameters cost both
        // APIs 2-20 % on the BVH (comparison/results/nvidia-h100/FINDINGS.md).
        Hit h = closest_hit(o, d);
        if (h.kind == 0u) {
            color += w * frame.background;
            continue;
        }

        vec3 p = o + h.t * d;
        vec3 ng;
        vec3 ns;
        uint mat_index;
        float scale = max_abs(o);
        if (h.kind == 1u) {
            Sphere s = sphere_buf.spheres[h.index];
            ng = (p - s.center) / s.radius;
            ns = ng;
            mat_index = s.material;
            // Sphere tests square their inputs (c = f.f - r^2), so a start a few
            // ULPs inside glass can still re-hit the same sphere: 4x the margin
            // (scenes/box's glass sphere speckled with 2^-22).
            scale = 4.0 * max(scale, max_abs(p));
        } else {
            Triangle tri = triangle_buf.triangles[h.index];
            // A triangle test's error grows with its vertices' magnitude (a floor
            // quad reaching x = 8 seen from a glass sphere at |o| = 1 re-hit itself).
            scale = max(scale, max(max_abs(tri.p0), max(max_abs(tri.p1), max_abs(tri.p2))));
            vec3 e1 = tri.p1 - tri.p0;
            vec3 e2 = tri.p2 - tri.p0;
#if defined(OFFSET_SCALE_AWARE) || defined(OFFSET_ULP)
            // These offsets assume p lies within a few ULPs of its coordinates
            // off the plane. o + t d does not: its error grows with t and with
            // how thin the triangle is (acne on the teapot's spout and handle).
            // Rebuilt from the barycentrics, an error in u, v only slides p
            // along the plane (Wachter & Binder, Ray Tracing Gems ch. 6).
            p = tri.p0 + h.u * e1 + h.v * e2;
#endif
            ng = normalize(cross(e1, e2));
            ns = normalize((1.0 - h.u - h.v) * tri.n0 + h.u * tri.n1 + h.v * tri.n2);
            mat_index = tri.material;
        }
        // Face both normals towards the incoming ray; `inside` tells glass which way it goes.
        bool inside = dot(d, ng) > 0.0;
        if (inside) {
            ng = -ng;
        }
        if (dot(ns, ng) < 0.0) {
            ns = -ns;
        }
        Material m = material_buf.materials[mat_index];

        vec3 local = m.ambient;
        for (uint li = 0u; li < LIGHT_COUNT; li++) {
            Light light = light_buf.lights[li];
            // The offset may depend on the direction (OFFSET_RAY): aim from p first.
            vec3 p_out = spawn_point(p, ng, normalize(light.position - p), scale);
            vec3 to_light = light.position - p_out;
            float dist = length(to_light);
            vec3 l = to_light / dist;
            float ndl = dot(ns, l);
            bool lit = ndl > 0.0 && dot(ng, l) > 0.0;
            if (lit) {
                // Stop a hair before the light: a light lying on a surface would
                // otherwise be hidden by that surface at the whim of rounding.
                lit = !occluded(p_out, l, dist * SHADOW_REACH);
            }
            if (lit) {
                vec3 r = reflect(-l, ns);
                float spec = pow(max(dot(r, -d), 0.0), m.shininess);
                local += light.color * (m.diffuse * ndl + m.specular * spec);
            }
        }
        color += w * local;

#if defined(HAS_MIRROR) || defined(HAS_GLASS)
        SPEC(SPEC_MIRROR || SPEC_GLASS)
        if (depth + 1u < max_depth) {
            float kr = m.reflectivity;
#ifdef HAS_GLASS
            float kt = m.transparency;
            SPEC(SPEC_GLASS)
            if (kt > 0.0) {
                float eta = inside ? m.ior : 1.0 / m.ior;
                // Near a smooth mesh's silhouette the interpolated normal can
                // face away from the ray (cos_i < 0), where Fresnel's formula
                // exceeds 1 and glass would send on more than arrived (F = 19.5
                // on a tilted-normal triangle). There Fresnel and the bend take
                // the geometric normal, which faces the ray, so F stays in
                // [0, 1]; the f64 reference does the same.
                vec3 nt = dot(d, ns) > 0.0 ? ng : ns;
                float cos_i = -dot(d, nt);
                float k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
                if (k < 0.0) {
                    kr += kt;  // total internal reflection
                } else {
                    float cos_t = sqrt(k);
                    float f = fresnel(cos_i, cos_t, eta);
                    kr += kt * f;
                    float wt = w * kt * (1.0 - f);
                    if (wt >= frame.min_weight && sp < STACK_SIZE) {
                        vec3 t_dir = normalize(eta * d + (eta * cos_i - cos_t) * nt);
                        RAY_PUSH(sp, spawn_point(p, -ng, t_dir, scale), t_dir, wt, depth + 1u);
                        sp += 1;
#ifdef COUNT_RAYS
                        rays_traced.glass_refracted += 1u;
#endif
                    }
                }
            }
#endif
            float wr = w * kr;
            if (wr >= frame.min_weight && sp < STACK_SIZE) {
                vec3 r_dir = reflect(d, ns);
                RAY_PUSH(sp, spawn_point(p, ng, r_dir, scale), r_dir, wr, depth + 1u);
                sp += 1;
#ifdef COUNT_RAYS
                if (m.transparency > 0.0) {
                    rays_traced.glass_reflected += 1u;
                } else {
                    rays_traced.mirror += 1u;
                }
#endif
            }
        }
#endif
    }
    return color;
}

vec3 primary_dir(vec2 frag_xy) {
    // top_left is relative to the eye, so this sum stays small and exact enough
    // however far the camera is from the origin.
    return normalize(frame.top_left + (frag_xy.x - 0.5) * frame.step_x + (frag_xy.y - 0.5) * frame.step_y);
}
