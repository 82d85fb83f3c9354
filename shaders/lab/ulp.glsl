// lab/ulp.glsl — the laboratory's arithmetic probe (`--experiment ulp --ulp-op OP`),
// compiled behind the tracer's declarations in place of its entry point
// (common/src/shader/build.rs). It measures what one f32 operation of the
// tracer gives on this driver; it traces nothing.
//
// Each result is one f32 (one component of a vector operation). Its inputs
// come from the result's index through an integer hash, which is exact on
// every GPU and which `twinray ulp` (comparison/src/ulp/inputs.rs) recomputes
// bit for bit, so the CPU knows every input without reading it back. The
// result's 32 bits travel in two neighbouring pixels, 16 bits each, as two
// bytes k/255 in red and green; blue holds a check byte of the pixel's index.
// The RGBA32F target and the PNG's quantisation (round(255 v)) give k back
// exactly, so the transport is lossless (`--ulp-op bits` checks it).
//
// ULP_OP_<NAME> selects the operation (one define, from common/src/lab).

uint ulp_hash(uint x) {
    // Chris Wellons' lowbias32: a full-avalanche 32-bit integer hash.
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// The input's class, shared by all its operands: 0-3 random (|x| in
// [2^-20, 2^21)), 4 within 64 ULPs of +-1, 5 tiny normals ([2^-126, 2^-102)),
// 6 denormals, 7 large ([2^100, 2^128)).
uint ulp_class(uint i) {
    return ulp_hash(i ^ 0xa511e9b3u) & 7u;
}

// The bits of operand slot `slot` of input `i`, of class `cls`.
uint ulp_operand(uint i, uint slot, uint cls) {
    uint h = ulp_hash(i * 16u + slot);
    uint g = ulp_hash(h ^ 0x9e3779b9u);
    uint sign = h & 0x80000000u;
    uint mant = h & 0x7fffffu;
    if (cls == 4u) {
        return (0x3f800000u + g % 129u - 64u) | (g & 0x80000000u);
    }
    uint biased = 107u + g % 41u;
    if (cls == 5u) {
        biased = 1u + g % 24u;
    }
    if (cls == 6u) {
        return sign | mant | 1u;
    }
    if (cls == 7u) {
        biased = 227u + g % 28u;
    }
    return sign | (biased << 23) | mant;
}

float ulp_float(uint i, uint slot) {
    return uintBitsToFloat(ulp_operand(i, slot, ulp_class(i)));
}

// A positive operand (sqrt, inversesqrt, pow's base).
float ulp_positive(uint i, uint slot) {
    return uintBitsToFloat(ulp_operand(i, slot, ulp_class(i)) & 0x7fffffffu);
}

// A positive number in [2^lo, 2^(lo + span)) whatever the class (pow's
// exponent, refract's eta).
float ulp_ranged(uint i, uint slot, uint lo, uint span) {
    uint h = ulp_hash(i * 16u + slot);
    uint g = ulp_hash(h ^ 0x9e3779b9u);
    return uintBitsToFloat(((lo + g % span) << 23) | (h & 0x7fffffu));
}

vec3 ulp_vec3(uint i, uint operand) {
    return vec3(ulp_float(i, operand * 3u), ulp_float(i, operand * 3u + 1u), ulp_float(i, operand * 3u + 2u));
}

// The total order of floats as unsigned integers: clamp's bounds are put in
// order without a float comparison the driver might flush.
uint ulp_key(uint b) {
    return (b & 0x80000000u) != 0u ? ~b : b | 0x80000000u;
}

// The bits of result `r`.
uint ulp_result(uint r) {
#if defined(ULP_OP_DOT) || defined(ULP_OP_LENGTH) || defined(ULP_OP_BITS) || defined(ULP_OP_ADD) || defined(ULP_OP_MUL) || defined(ULP_OP_DIV) || defined(ULP_OP_SQRT) || defined(ULP_OP_INVERSESQRT) || defined(ULP_OP_POW) || defined(ULP_OP_FMA) || defined(ULP_OP_MIN) || defined(ULP_OP_MAX) || defined(ULP_OP_CLAMP)
    uint i = r;
#else
    // Vector results: three per input, one per component.
    uint i = r / 3u;
    uint c = r % 3u;
#endif
    float x = 0.0;
#ifdef ULP_OP_BITS
    return ulp_operand(i, 0u, ulp_class(i));
#endif
#ifdef ULP_OP_ADD
    x = ulp_float(i, 0u) + ulp_float(i, 1u);
#endif
#ifdef ULP_OP_MUL
    x = ulp_float(i, 0u) * ulp_float(i, 1u);
#endif
#ifdef ULP_OP_DIV
    x = ulp_float(i, 0u) / ulp_float(i, 1u);
#endif
#ifdef ULP_OP_SQRT
    x = sqrt(ulp_positive(i, 0u));
#endif
#ifdef ULP_OP_INVERSESQRT
    x = inversesqrt(ulp_positive(i, 0u));
#endif
#ifdef ULP_OP_POW
    // The exponent in [2^-3, 2^7), as the tracer's shininess: pow is
    // undefined for a base of 0 with a non-positive exponent.
    x = pow(ulp_positive(i, 0u), ulp_ranged(i, 1u, 124u, 10u));
#endif
#ifdef ULP_OP_FMA
    x = fma(ulp_float(i, 0u), ulp_float(i, 1u), ulp_float(i, 2u));
#endif
#ifdef ULP_OP_MIN
    x = min(ulp_float(i, 0u), ulp_float(i, 1u));
#endif
#ifdef ULP_OP_MAX
    x = max(ulp_float(i, 0u), ulp_float(i, 1u));
#endif
#ifdef ULP_OP_CLAMP
    uint cls = ulp_class(i);
    uint a = ulp_operand(i, 1u, cls);
    uint b = ulp_operand(i, 2u, cls);
    bool swap = ulp_key(b) < ulp_key(a);
    uint lo = swap ? b : a;
    uint hi = swap ? a : b;
    x = clamp(ulp_float(i, 0u), uintBitsToFloat(lo), uintBitsToFloat(hi));
#endif
#ifdef ULP_OP_DOT
    x = dot(ulp_vec3(i, 0u), ulp_vec3(i, 1u));
#endif
#ifdef ULP_OP_LENGTH
    x = length(ulp_vec3(i, 0u));
#endif
#ifdef ULP_OP_NORMALIZE
    x = normalize(ulp_vec3(i, 0u))[c];
#endif
#ifdef ULP_OP_CROSS
    x = cross(ulp_vec3(i, 0u), ulp_vec3(i, 1u))[c];
#endif
#ifdef ULP_OP_REFLECT
    x = reflect(ulp_vec3(i, 0u), ulp_vec3(i, 1u))[c];
#endif
#ifdef ULP_OP_REFRACT
    // eta in [0.5, 2), as glass's ratios of indices.
    x = refract(ulp_vec3(i, 0u), ulp_vec3(i, 1u), ulp_ranged(i, 6u, 126u, 2u))[c];
#endif
    return floatBitsToUint(x);
}

// Pixel `pixel` of the probe's image: the high (even pixel) or low (odd
// pixel) 16 bits of its result as two bytes, and the check byte.
vec4 ulp_pixel(uint pixel) {
    uint bits = ulp_result(pixel >> 1);
    uint half16 = (pixel & 1u) == 0u ? bits >> 16 : bits & 0xffffu;
    uint check = ulp_hash(pixel ^ 0x5bd1e995u) & 0xffu;
    return vec4(float(half16 >> 8), float(half16 & 0xffu), float(check), 255.0) * (1.0 / 255.0);
}

#ifdef ULP_COMPUTE
layout(local_size_x = WG_X, local_size_y = WG_Y, local_size_z = 1) in;

layout(rgba32f, set = 0, binding = 5) uniform writeonly image2D out_image;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= frame.width || p.y >= frame.height) {
        return;
    }
    imageStore(out_image, ivec2(p), ulp_pixel(p.y * frame.width + p.x));
}
#else
layout(location = 0) out vec4 out_color;

// Row y of the image is gl_FragCoord.y = y + 0.5 in both APIs (docs/architecture.md#orientation).
void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    out_color = ulp_pixel(p.y * frame.width + p.x);
}
#endif
