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

bool sphere_blocks(vec3 origin, vec3 dir, float dist, uint i) {
    return i < SPHERE_COUNT && hit_sphere(origin, dir, sphere_buf.spheres[i], 0.0, dist) > 0.0;
}

bool triangle_blocks(TriRay ray, float dist, uint i) {
    return i < TRIANGLE_COUNT && hit_triangle(ray, triangle_buf.triangles[i], 0.0, dist).x > 0.0;
}

// Shadow rays need any hit before the light, not the closest one.
bool occluded_brute(vec3 origin, vec3 dir, float dist) {
#ifdef HAS_SPHERES
    SPEC(SPEC_SPHERES) {
        for (uint i = 0u; i < SPHERE_COUNT; i += PRIMS_PER_ITERATION) {
            if (sphere_blocks(origin, dir, dist, i) || sphere_blocks(origin, dir, dist, i + 1u)
                || sphere_blocks(origin, dir, dist, i + 2u) || sphere_blocks(origin, dir, dist, i + 3u)) {
                return true;
            }
        }
    }
#endif
#ifdef HAS_TRIANGLES
    SPEC(SPEC_TRIANGLES) {
        TriRay ray = tri_ray(origin, dir);
        for (uint i = 0u; i < TRIANGLE_COUNT; i += PRIMS_PER_ITERATION) {
            if (triangle_blocks(ray, dist, i) || triangle_blocks(ray, dist, i + 1u)
                || triangle_blocks(ray, dist, i + 2u) || triangle_blocks(ray, dist, i + 3u)) {
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


#ifdef ONE_QUERY
// --experiment one-query: both questions behind one call, for the ray loop's
// single query site (trace/loop.glsl).
Hit query(vec3 origin, vec3 dir, float t_max, bool any_hit) {
#ifdef USE_BVH
    return traverse(origin, dir, t_max, any_hit);
#else
    if (any_hit) {
        Hit h;
        h.t = t_max;
        h.kind = occluded_brute(origin, dir, t_max) ? 1u : 0u;
        h.index = 0u;
        h.u = 0.0;
        h.v = 0.0;
        return h;
    }
    return closest_hit_brute(origin, dir);
#endif
}
#endif
