// trace/loop.glsl — the ray loop with its Phong shading, shadow, mirror and
// glass rays; the last part of the tracer.
//
// The tracer's parts, what each holds and how they are put together:
// docs/architecture.md#the-tracers-parts
//
// Features a scene lacks are compiled out through defines chosen in
// common's shader module: HAS_SPHERES, HAS_TRIANGLES, HAS_MIRROR, HAS_GLASS,
// and STACK_SIZE (the ray stack: with glass max_depth entries, Features::ray_stack_entries
// in common/src/scene/mod.rs says why that is enough, and by brute force one more;
// without glass 1).
// LIGHT_BEFORE_WALK reorders one light's shading for OpenGL's BVH walks (SHADE).
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
// invocation needs (docs/findings/opengl-compute.md#what-closed-the-gap). RAY_STACK_SPLIT (--experiment
// split-ray-stack) puts back the four arrays. The depth is a small integer,
// exact as a float.
#ifdef RAY_STACK_SPLIT
#define RAY_STACK_DECLARE vec3 st_origin[STACK_SIZE]; vec3 st_dir[STACK_SIZE]; float st_weight[STACK_SIZE]; uint st_depth[STACK_SIZE]
#define RAY_PUSH(i, o, d, w, depth) st_origin[i] = (o); st_dir[i] = (d); st_weight[i] = (w); st_depth[i] = (depth)
#define RAY_POP(i) o = st_origin[i]; d = st_dir[i]; w = st_weight[i]; depth = st_depth[i]
#elif STACK_SIZE == 1
// One entry (no glass): plain variables, which take no local memory where
// one-element arrays did (NVIDIA's OpenGL: the 4-wide teapot's tracer 272 B
// to 240 B, under the 254 B past which that driver idles multiprocessors).
// The index is always 0.
#define RAY_STACK_DECLARE vec4 st_origin_weight; vec4 st_dir_depth
#define RAY_PUSH(i, o, d, w, depth) st_origin_weight = vec4((o), (w)); st_dir_depth = vec4((d), float(depth))
#define RAY_POP(i) o = st_origin_weight.xyz; w = st_origin_weight.w; d = st_dir_depth.xyz; depth = uint(st_dir_depth.w)
#else
#define RAY_STACK_DECLARE vec4 st_origin_weight[STACK_SIZE]; vec4 st_dir_depth[STACK_SIZE]
#define RAY_PUSH(i, o, d, w, depth) st_origin_weight[i] = vec4((o), (w)); st_dir_depth[i] = vec4((d), float(depth))
#define RAY_POP(i) o = st_origin_weight[i].xyz; w = st_origin_weight[i].w; d = st_dir_depth[i].xyz; depth = uint(st_dir_depth[i].w)
#endif

// Mirror and glass push rays, so the tracer pops until none is left. Without
// them a pixel has its one ray and no loop: NVIDIA's OpenGL compiler kept the
// loop of one turn in its machine code (its Vulkan compiler removed it), and
// held the colour and the material's shininess in shared memory across it.
// Without the loop OpenGL's 1080p and 4K teapot frames are 3.6 and 5.5 %
// shorter (its million-triangle ones 2 % longer, for a reason not found);
// Vulkan's do not move
// (docs/findings/opengl-compute.md#what-closed-the-gap; data: f8d14ba:comparison/results/nvidia-h100/investigation/one-ray/).
#if defined(HAS_MIRROR) || defined(HAS_GLASS)
#define RAY_LOOP while (sp > 0)
#else
#define RAY_LOOP
#endif

// The hit's Phong shading with its shadow rays (SHADE, a macro: the ray loop
// calls it before or after it pushes the hit's secondary rays, and a macro
// cannot hold the preprocessor lines of the push).
//
// LIGHT_BEFORE_WALK: OpenGL's BVH walks in a scene of one light (the sphere
// list; common's plan decides, Api::light_before_walk). The mirror and glass
// rays go on the stack first, and the light is shaded before its shadow walk,
// whose ray is then rebuilt from the light's position: across the walk only
// the spawn point's inputs and the light's share stay live, not the normals,
// the view direction and the material. NVIDIA's OpenGL then holds 28 warps a
// multiprocessor on the sphere list instead of 24, and its 1080p frames are
// 6-7 % shorter; its Vulkan compiler gains nothing and loses 1-4 %, and a box
// of glass on OpenGL's fragment path lost 6 %, so only that path and API take
// it (docs/findings/opengl-compute.md#the-one-lights-share-before-its-walk-h200;
// --experiment walk-then-shade turns it off). The operations and their order
// are the loop's: the same image.
//
// A shadow ray stops a hair before the light (SHADOW_REACH): a light lying on
// a surface would otherwise be hidden by that surface at the whim of rounding.

// The shadow ray from p to a light at `position`: its start p_out, its
// direction l and its length dist. The offset may depend on the direction
// (OFFSET_RAY), so the ray aims from p first.
#define LIGHT_RAY(position)                                                              \
    vec3 p_out = spawn_point(p, ng, normalize((position) - p), scale);                   \
    vec3 to_light = (position) - p_out;                                                  \
    float dist = length(to_light);                                                       \
    vec3 l = to_light / dist;
#ifdef LIGHT_BEFORE_WALK
#define SHADE()                                                                          \
    {                                                                                    \
        vec3 local = m.ambient;                                                          \
        vec3 share = vec3(0.0);                                                          \
        bool lit = false;                                                                \
        {                                                                                \
            Light light = light_buf.lights[0];                                           \
            LIGHT_RAY(light.position)                                                    \
            float ndl = dot(ns, l);                                                      \
            if (ndl > 0.0 && dot(ng, l) > 0.0) {                                         \
                vec3 r = reflect(-l, ns);                                                \
                float spec = pow(max(dot(r, -d), 0.0), m.shininess);                     \
                share = light.color * (m.diffuse * ndl + m.specular * spec);             \
                lit = true;                                                              \
            }                                                                            \
        }                                                                                \
        if (lit) {                                                                       \
            vec3 position = light_buf.lights[0].position;                                \
            LIGHT_RAY(position)                                                          \
            if (!occluded(p_out, l, dist * SHADOW_REACH)) {                              \
                local += share;                                                          \
            }                                                                            \
        }                                                                                \
        color += w * local;                                                              \
    }
#else
#define SHADE()                                                                          \
    {                                                                                    \
        vec3 local = m.ambient;                                                          \
        for (uint li = 0u; li < LIGHT_COUNT; li++) {                                     \
            Light light = light_buf.lights[li];                                          \
            LIGHT_RAY(light.position)                                                    \
            float ndl = dot(ns, l);                                                      \
            bool lit = ndl > 0.0 && dot(ng, l) > 0.0;                                    \
            if (lit) {                                                                   \
                lit = !occluded(p_out, l, dist * SHADOW_REACH);                          \
            }                                                                            \
            if (lit) {                                                                   \
                vec3 r = reflect(-l, ns);                                                \
                float spec = pow(max(dot(r, -d), 0.0), m.shininess);                     \
                local += light.color * (m.diffuse * ndl + m.specular * spec);            \
            }                                                                            \
        }                                                                                \
        color += w * local;                                                              \
    }
#endif

vec3 trace(vec3 origin, vec3 dir) {
    RAY_STACK_DECLARE;
#ifdef HAS_GLASS
    // Glass pushes two rays per hit: the stack's size bounds the depth.
    uint max_depth = min(frame.max_depth, uint(STACK_SIZE));
#else
    // A mirror pushes one ray after popping one: one slot serves any depth.
    uint max_depth = frame.max_depth;
#endif

    vec3 color = vec3(0.0);
    int sp = 0;
    RAY_PUSH(0, origin, dir, 1.0, 0u);
    sp = 1;

    RAY_LOOP {
        sp -= 1;
        vec3 o;
        vec3 d;
        float w;
        uint depth;
        RAY_POP(sp);

        // The shading stays written out here rather than in functions: naga's
        // output for a struct returned by value and `out` parameters cost both
        // APIs time on every BVH point
        // (docs/findings/shader-compilers.md#what-naga-adds-and-what-the-source-now-says).
        Hit h = closest_hit(o, d);
        if (h.kind == 0u) {
            color += w * frame.background;
        } else {
            vec3 p = o + h.t * d;
            vec3 ng;
            vec3 ns;
            uint mat_index;
            float scale = max_abs(o);
            if (h.kind == 1u) {
                Sphere s = sphere_buf.spheres[h.index];
                // One Newton step on |o + t d - c|^2 = r^2 from the test's t: the
                // test's division and square root are approximate on GPUs (2 to 3
                // ULPs of t, which refraction through nested glass magnifies into
                // visible error); the step's residual is exactly rounded arithmetic,
                // relative to the sphere rather than to t. Near tangency, where
                // the step is ill-conditioned (its size past 2^-10 radii, or NaN),
                // t stays.
                vec3 rel = (o - s.center) + h.t * d;
                float dt = (dot(rel, rel) - s.radius * s.radius) / (2.0 * dot(rel, d));
                if (abs(dt) < s.radius * (1.0 / 1024.0)) {
                    p = o + (h.t - dt) * d;
                }
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

#ifndef LIGHT_BEFORE_WALK
            SHADE();
#endif
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
#ifdef LIGHT_BEFORE_WALK
            SHADE();
#endif
        }
    }
    return color;
}

vec3 primary_dir(vec2 frag_xy) {
    // top_left is relative to the eye, so this sum stays small and exact enough
    // however far the camera is from the origin.
    return normalize(frame.top_left + (frag_xy.x - 0.5) * frame.step_x + (frag_xy.y - 0.5) * frame.step_y);
}
