// trace.glsl — the one Whitted-style tracer shared by every entry point.
//
// Rust concatenates: a `#version` line, this file, then an entry point (trace.frag
// or trace.comp).
// naga has no #include. Every struct here is mirrored by a #[repr(C)] struct in
// common/src/gpu.rs and a test checks that naga's layout equals the Rust one.
//
// Features a scene lacks are compiled out through defines chosen in
// common/src/shader.rs: HAS_SPHERES, HAS_TRIANGLES, HAS_MIRROR, HAS_GLASS,
// and STACK_SIZE (the ray stack, >= max_depth + 1).
//
// The CPU reference (common/src/reference.rs) follows this file step by step in
// f64; change both together.

#ifndef STACK_SIZE
#define STACK_SIZE 17
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
    vec3 top_left;
    float epsilon;
    vec3 step_x;
    uint max_depth;
    vec3 step_y;
    uint sphere_count;
    vec3 background;
    uint triangle_count;
    uint light_count;
    uint width;   // image size in pixels: the compute entry point's bounds check
    uint height;
    uint pad;
} frame;

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

// The BVH (common/src/bvh.rs), depth-first: an interior node's left child is the
// next node and `left_or_first` its right child; a leaf (count > 0) holds
// prims[left_or_first .. +count], each a triangle index or a sphere index with
// the top bit set. Bound always; read only by the USE_BVH variant.
struct BvhNode {
    vec3 bmin;
    uint left_or_first;
    vec3 bmax;
    uint count;
};

layout(std430, set = 0, binding = 6) readonly buffer BvhNodes {
    BvhNode nodes[];
} bvh_buf;

layout(std430, set = 0, binding = 7) readonly buffer BvhPrims {
    uint prims[];
} prim_buf;

const float T_MAX = 1.0e30;

// Stable ray-sphere test (Haines et al., Ray Tracing Gems ch. 7): the discriminant
// is formed from the distance of the centre to the ray, and the two roots as c/q
// and q, which avoids cancellation for small or far spheres. `dir` is unit length.
// It takes the fields it needs, not a `Sphere`: naga turns a struct argument into
// a load of the whole struct from the storage buffer (see the Performance notes).
float hit_sphere(vec3 origin, vec3 dir, vec3 center, float radius, float t_min, float t_max) {
    vec3 f = origin - center;
    float b = dot(f, dir);
    vec3 l = f - b * dir;
    float r2 = radius * radius;
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
    if (lo > t_min && lo < t_max) {
        return lo;
    }
    if (hi > t_min && hi < t_max) {
        return hi;
    }
    return -1.0;
}

// Moller-Trumbore. Conditions are written so that NaN (degenerate triangles give
// det == 0 or a tiny det) fails them: a degenerate triangle is never hit.
vec3 hit_triangle(vec3 origin, vec3 dir, vec3 p0, vec3 p1, vec3 p2, float t_min, float t_max) {
    vec3 e1 = p1 - p0;
    vec3 e2 = p2 - p0;
    vec3 pv = cross(dir, e2);
    float det = dot(e1, pv);
    vec3 miss = vec3(-1.0, 0.0, 0.0);
    if (det == 0.0) {
        return miss;
    }
    float inv = 1.0 / det;
    vec3 tv = origin - p0;
    float u = dot(tv, pv) * inv;
    if (!(u >= 0.0 && u <= 1.0)) {
        return miss;
    }
    vec3 qv = cross(tv, e1);
    float v = dot(dir, qv) * inv;
    if (!(v >= 0.0 && u + v <= 1.0)) {
        return miss;
    }
    float t = dot(e2, qv) * inv;
    if (!(t > t_min && t < t_max)) {
        return miss;
    }
    return vec3(t, u, v);
}

float sphere_t(vec3 origin, vec3 dir, uint i, float t_max) {
    return hit_sphere(origin, dir, sphere_buf.spheres[i].center, sphere_buf.spheres[i].radius, 0.0, t_max);
}

vec3 triangle_tuv(vec3 origin, vec3 dir, uint i, float t_max) {
    return hit_triangle(origin, dir, triangle_buf.triangles[i].p0, triangle_buf.triangles[i].p1,
                        triangle_buf.triangles[i].p2, 0.0, t_max);
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

void closest_sphere(inout Hit h, vec3 origin, vec3 dir, uint i, uint n) {
    if (i < n) {
        float t = sphere_t(origin, dir, i, h.t);
        if (t > 0.0) {
            h.t = t;
            h.kind = 1u;
            h.index = i;
        }
    }
}

void closest_triangle(inout Hit h, vec3 origin, vec3 dir, uint i, uint n) {
    if (i < n) {
        vec3 r = triangle_tuv(origin, dir, i, h.t);
        if (r.x > 0.0) {
            h.t = r.x;
            h.kind = 2u;
            h.index = i;
            h.u = r.y;
            h.v = r.z;
        }
    }
}

#ifdef USE_BVH
#ifndef BVH_STACK
#define BVH_STACK 64
#endif
const uint SPHERE_BIT = 0x80000000u;

// Where the ray enters the box, or -1 if it misses it before t_max. Zero
// direction components are nudged so 0 * inf never makes a NaN.
float enter_box(vec3 origin, vec3 inv_dir, uint node, float t_max) {
    vec3 t0 = (bvh_buf.nodes[node].bmin - origin) * inv_dir;
    vec3 t1 = (bvh_buf.nodes[node].bmax - origin) * inv_dir;
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

// Visits the tree near child first and skips subtrees that start beyond the
// closest hit so far. With `any_hit` (shadow rays) it stops at the first hit
// before t_max and reports it with kind != 0.
Hit traverse(vec3 origin, vec3 dir, float t_max, bool any_hit) {
    Hit h;
    h.t = t_max;
    h.kind = 0u;
    h.index = 0u;
    h.u = 0.0;
    h.v = 0.0;
    vec3 inv_dir = inverse_dir(dir);
    uint stack_node[BVH_STACK];
    float stack_t[BVH_STACK];
    int sp = 0;
    if (enter_box(origin, inv_dir, 0u, t_max) < 0.0) {
        return h;
    }
    uint node = 0u;
    while (true) {
        uint count = bvh_buf.nodes[node].count;
        uint first = bvh_buf.nodes[node].left_or_first;
        if (count > 0u) {
            for (uint k = 0u; k < count; k++) {
                uint prim = prim_buf.prims[first + k];
                if ((prim & SPHERE_BIT) != 0u) {
                    uint i = prim & ~SPHERE_BIT;
                    float t = sphere_t(origin, dir, i, h.t);
                    if (t > 0.0) {
                        h.t = t;
                        h.kind = 1u;
                        h.index = i;
                    }
                } else {
                    vec3 r = triangle_tuv(origin, dir, prim, h.t);
                    if (r.x > 0.0) {
                        h.t = r.x;
                        h.kind = 2u;
                        h.index = prim;
                        h.u = r.y;
                        h.v = r.z;
                    }
                }
                if (any_hit && h.kind != 0u) {
                    return h;
                }
            }
        } else {
            uint left = node + 1u;
            uint right = first;
            float tl = enter_box(origin, inv_dir, left, h.t);
            float tr = enter_box(origin, inv_dir, right, h.t);
            if (tl >= 0.0 && tr >= 0.0) {
                bool left_first = tl <= tr;
                node = left_first ? left : right;
                if (sp < BVH_STACK) {
                    stack_node[sp] = left_first ? right : left;
                    stack_t[sp] = left_first ? tr : tl;
                    sp += 1;
                }
                continue;
            }
            if (tl >= 0.0) {
                node = left;
                continue;
            }
            if (tr >= 0.0) {
                node = right;
                continue;
            }
        }
        // Pop the nearest pending subtree that can still hold a closer hit.
        bool found = false;
        while (sp > 0 && !found) {
            sp -= 1;
            if (stack_t[sp] < h.t) {
                node = stack_node[sp];
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

Hit closest_hit_brute(vec3 origin, vec3 dir) {
    Hit h;
    h.t = T_MAX;
    h.kind = 0u;
    h.index = 0u;
    h.u = 0.0;
    h.v = 0.0;
#ifdef HAS_SPHERES
    uint spheres = frame.sphere_count;
    for (uint i = 0u; i < spheres; i += PRIMS_PER_ITERATION) {
        closest_sphere(h, origin, dir, i, spheres);
        closest_sphere(h, origin, dir, i + 1u, spheres);
        closest_sphere(h, origin, dir, i + 2u, spheres);
        closest_sphere(h, origin, dir, i + 3u, spheres);
    }
#endif
#ifdef HAS_TRIANGLES
    uint triangles = frame.triangle_count;
    for (uint i = 0u; i < triangles; i += PRIMS_PER_ITERATION) {
        closest_triangle(h, origin, dir, i, triangles);
        closest_triangle(h, origin, dir, i + 1u, triangles);
        closest_triangle(h, origin, dir, i + 2u, triangles);
        closest_triangle(h, origin, dir, i + 3u, triangles);
    }
#endif
    return h;
}

bool sphere_blocks(vec3 origin, vec3 dir, float dist, uint i, uint n) {
    return i < n && sphere_t(origin, dir, i, dist) > 0.0;
}

bool triangle_blocks(vec3 origin, vec3 dir, float dist, uint i, uint n) {
    return i < n && triangle_tuv(origin, dir, i, dist).x > 0.0;
}

// Shadow rays need any hit before the light, not the closest one.
bool occluded_brute(vec3 origin, vec3 dir, float dist) {
#ifdef HAS_SPHERES
    uint spheres = frame.sphere_count;
    for (uint i = 0u; i < spheres; i += PRIMS_PER_ITERATION) {
        if (sphere_blocks(origin, dir, dist, i, spheres) || sphere_blocks(origin, dir, dist, i + 1u, spheres)
            || sphere_blocks(origin, dir, dist, i + 2u, spheres) || sphere_blocks(origin, dir, dist, i + 3u, spheres)) {
            return true;
        }
    }
#endif
#ifdef HAS_TRIANGLES
    uint triangles = frame.triangle_count;
    for (uint i = 0u; i < triangles; i += PRIMS_PER_ITERATION) {
        if (triangle_blocks(origin, dir, dist, i, triangles) || triangle_blocks(origin, dir, dist, i + 1u, triangles)
            || triangle_blocks(origin, dir, dist, i + 2u, triangles) || triangle_blocks(origin, dir, dist, i + 3u, triangles)) {
            return true;
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
#ifdef USE_BVH
    return traverse(origin, dir, dist, true).kind != 0u;
#else
    return occluded_brute(origin, dir, dist);
#endif
}

// Secondary rays start a small, scale-aware distance off the surface, along the
// geometric normal on the side the new ray leaves from.
vec3 offset_point(vec3 p, vec3 n) {
    float scale = max(1.0, max(abs(p.x), max(abs(p.y), abs(p.z))));
    return p + n * (frame.epsilon * scale);
}

// Unpolarised Fresnel reflectance of a dielectric boundary.
float fresnel(float cos_i, float cos_t, float eta) {
    float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

vec3 trace(vec3 origin, vec3 dir) {
    vec3 st_origin[STACK_SIZE];
    vec3 st_dir[STACK_SIZE];
    float st_weight[STACK_SIZE];
    uint st_depth[STACK_SIZE];
    uint max_depth = min(frame.max_depth, uint(STACK_SIZE - 1));

    vec3 color = vec3(0.0);
    int sp = 0;
    st_origin[0] = origin;
    st_dir[0] = dir;
    st_weight[0] = 1.0;
    st_depth[0] = 0u;
    sp = 1;

    while (sp > 0) {
        sp -= 1;
        vec3 o = st_origin[sp];
        vec3 d = st_dir[sp];
        float w = st_weight[sp];
        uint depth = st_depth[sp];

        Hit h = closest_hit(o, d);
        if (h.kind == 0u) {
            color += w * frame.background;
            continue;
        }

        vec3 p = o + h.t * d;
        vec3 ng;
        vec3 ns;
        uint mat_index;
        if (h.kind == 1u) {
            Sphere s = sphere_buf.spheres[h.index];
            ng = (p - s.center) / s.radius;
            ns = ng;
            mat_index = s.material;
        } else {
            Triangle tri = triangle_buf.triangles[h.index];
            ng = normalize(cross(tri.p1 - tri.p0, tri.p2 - tri.p0));
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
        vec3 p_out = offset_point(p, ng);
        uint light_count = frame.light_count;
        for (uint li = 0u; li < light_count; li++) {
            Light light = light_buf.lights[li];
            vec3 to_light = light.position - p_out;
            float dist = length(to_light);
            vec3 l = to_light / dist;
            float ndl = dot(ns, l);
            bool lit = ndl > 0.0 && dot(ng, l) > 0.0;
            if (lit) {
                lit = !occluded(p_out, l, dist);
            }
            if (lit) {
                vec3 r = reflect(-l, ns);
                float spec = pow(max(dot(r, -d), 0.0), m.shininess);
                local += light.color * (m.diffuse * ndl + m.specular * spec);
            }
        }
        color += w * local;

#if defined(HAS_MIRROR) || defined(HAS_GLASS)
        if (depth + 1u < max_depth) {
            float kr = m.reflectivity;
#ifdef HAS_GLASS
            float kt = m.transparency;
            if (kt > 0.0) {
                float eta = inside ? m.ior : 1.0 / m.ior;
                float cos_i = -dot(d, ns);
                float k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
                if (k < 0.0) {
                    kr += kt;  // total internal reflection
                } else {
                    float cos_t = sqrt(k);
                    float f = fresnel(cos_i, cos_t, eta);
                    kr += kt * f;
                    float wt = w * kt * (1.0 - f);
                    if (wt >= frame.min_weight && sp < STACK_SIZE) {
                        st_origin[sp] = offset_point(p, -ng);
                        st_dir[sp] = normalize(eta * d + (eta * cos_i - cos_t) * ns);
                        st_weight[sp] = wt;
                        st_depth[sp] = depth + 1u;
                        sp += 1;
                    }
                }
            }
#endif
            float wr = w * kr;
            if (wr >= frame.min_weight && sp < STACK_SIZE) {
                st_origin[sp] = p_out;
                st_dir[sp] = reflect(d, ns);
                st_weight[sp] = wr;
                st_depth[sp] = depth + 1u;
                sp += 1;
            }
        }
#endif
    }
    return color;
}

vec3 primary_dir(vec2 frag_xy) {
    vec3 target = frame.top_left + (frag_xy.x - 0.5) * frame.step_x + (frag_xy.y - 0.5) * frame.step_y;
    return normalize(target - frame.eye);
}
