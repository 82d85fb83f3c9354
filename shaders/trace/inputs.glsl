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
    uint launch_grid;  // tiles across << 16 | down, of the launch order; 0: none (trace.comp)
} frame;

// Every variant an app runs bakes the counts in (Variant::with_scene_data);
// only the scene-independent generic variant of the tests, and
// --experiment uniform-counts, read them from the uniform.
#ifndef SPHERE_COUNT
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

#ifdef USE_BVH_WIDE
// The wide tree's nodes take binding 6 instead (common/src/scene/accel/wide.rs,
// gpu::layout::GpuBvhWideNode): four children's boxes a struct, one vec4 per
// corner coordinate; an 8-wide node is two consecutive ones (BVH_WIDE_QUADS).
// A slot without a child holds NO_CHILD and a box no ray enters.
struct BvhWideNode {
    // min_x, min_y, min_z, max_x, max_y, max_z (the Rust struct's fields), as
    // an array so that the walk reads each axis's near and far planes by the
    // sign of the ray's direction.
    vec4 bounds[6];
    uvec4 child;
};

layout(std430, set = 0, binding = 6) readonly buffer BvhWideNodes {
    BvhWideNode nodes[];
} bvh_wide_buf;
#else
layout(std430, set = 0, binding = 6) readonly buffer BvhNodes {
    BvhNode nodes[];
} bvh_buf;
#endif

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

