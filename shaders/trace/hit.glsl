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
// runs fastest (early exits after each were slower on the brute-force points:
// docs/findings/shader-compilers.md#what-naga-adds-and-what-the-source-now-says);
// the index is clamped so that the tests past the last primitive
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

