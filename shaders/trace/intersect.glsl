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

#ifndef TRIANGLE_WATERTIGHT
// Moller-Trumbore 1997, from p0 and the edges E1 = p1 - p0, E2 = p2 - p0,
// returning (t, u, v) or `miss` from the function it is written into: a
// macro, so that hit_triangle (the brute-force loops) compiles to exactly
// what it did before the BVH's leaves took their own copy (NVIDIA's OpenGL
// fragment path ran the box 2 % slower through a shared function).
#define MOLLER_TRUMBORE(P0, E1, E2, DEGENERATE)                                 \
    vec3 pv = cross(r.d, E2);                                                   \
    float det = dot(E1, pv);                                                    \
    if (det == 0.0) {                                                           \
        return miss;                                                            \
    }                                                                           \
    float inv = 1.0 / det;                                                      \
    vec3 tv = r.o - P0;                                                         \
    float u = dot(tv, pv) * inv;                                                \
    if (!(u >= 0.0 && u <= 1.0)) {                                              \
        return miss;                                                            \
    }                                                                           \
    vec3 qv = cross(tv, E1);                                                    \
    float v = dot(r.d, qv) * inv;                                               \
    if (!(v >= 0.0 && u + v <= 1.0)) {                                          \
        return miss;                                                            \
    }                                                                           \
    float t = dot(E2, qv) * inv;                                                \
    bool degenerate = DEGENERATE;                                               \
    if (!(t > t_min && t < t_max) || degenerate) {                              \
        return miss;                                                            \
    }                                                                           \
    return vec3(t, u, v);

#ifdef USE_BVH
// The BVH's leaves hold p0 and the edges already subtracted (the same f32
// subtraction, made once on the CPU: common/src/gpu/upload.rs), which saves
// every leaf test six subtractions (docs/findings/bvh.md#the-leaves-edges-and-vulkans-stack-h200).
// The degenerate test is is_degenerate's, on the edges.
bool edges_degenerate(vec3 e1, vec3 e2) {
    vec3 c = cross(e1, e2);
    return c.x == 0.0 && c.y == 0.0 && c.z == 0.0;
}

vec3 moller_trumbore(TriRay r, vec3 p0, vec3 e1, vec3 e2, float t_min, float t_max) {
    vec3 miss = vec3(-1.0, 0.0, 0.0);
    MOLLER_TRUMBORE(p0, e1, e2, edges_degenerate(e1, e2))
}
#endif
#endif

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
    // inside the branch, along with early exits in the shadow test, was
    // slower on the brute-force points:
    // docs/findings/shader-compilers.md#what-naga-adds-and-what-the-source-now-says).
    bool degenerate = is_degenerate(tri);
    if (!(t > t_min && t < t_max) || degenerate) {
        return miss;
    }
    return vec3(t, ev * inv, ew * inv);
#else
    vec3 e1 = tri.p1 - tri.p0;
    vec3 e2 = tri.p2 - tri.p0;
    // Computed on every call, as naga always did for the call right of `||`
    // this once was (the product's timings include it; testing it only
    // inside the branch, along with early exits in the shadow test, was
    // slower on the brute-force points:
    // docs/findings/shader-compilers.md#what-naga-adds-and-what-the-source-now-says).
    MOLLER_TRUMBORE(tri.p0, e1, e2, is_degenerate(tri))
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

