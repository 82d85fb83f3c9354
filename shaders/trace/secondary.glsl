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

