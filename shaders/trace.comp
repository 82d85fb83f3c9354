// trace.comp — compute entry point: the same tracer, one invocation per pixel,
// written to an RGBA32F storage image instead of a colour attachment.
//
// Pixel (x, y) is gl_GlobalInvocationID.xy with y counted from the top, and the
// primary ray goes through its centre, (x, y) + 0.5: exactly the gl_FragCoord
// the fragment path sees in Vulkan. Image row 0 is therefore the top row in both
// APIs, and a plain copy/readback of the image gives the upright picture.
//
// WG_X x WG_Y is the workgroup size, set per run through naga defines
// (common/src/shader/build.rs); the dispatch is ceil(width / WG_X) x ceil(height / WG_Y),
// so invocations past the right and bottom edges return at once.

#ifndef WG_X
#define WG_X 8
#endif
#ifndef WG_Y
#define WG_Y 4
#endif

layout(local_size_x = WG_X, local_size_y = WG_Y, local_size_z = 1) in;

layout(rgba32f, set = 0, binding = 5) uniform writeonly image2D out_image;

#ifdef SHARED_PAD_KIB
// --shared-pad (a measurement): workgroup memory the tracer does not need. A
// driver splits each multiprocessor's memory between shared memory and L1
// cache by what its shaders declare, and fits fewer workgroups once shared
// memory runs out; this shows what either does to the time. Each invocation
// writes one word, spread across the whole array, and reads it back through an
// index the compiler cannot prove equal (frame.pad is always 0), so no
// compiler can drop the array, and no invocation reads another's word.
shared uint shared_pad[SHARED_PAD_KIB * 256];
#endif

void main() {
#ifdef SHARED_PAD_KIB
    uint group = uint(WG_X * WG_Y);
    uint stride = uint(SHARED_PAD_KIB * 256) / group;
    shared_pad[gl_LocalInvocationIndex * stride] = gl_LocalInvocationIndex;
    if (shared_pad[((gl_LocalInvocationIndex + frame.pad) % group) * stride] == 0xffffffffu) {
        return;
    }
#endif
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= frame.width || p.y >= frame.height) {
        return;
    }
#ifdef COUNT_RAYS
    rays_traced = RayCount(1u, 0u, 0u, 0u, 0u);
#endif
    vec3 dir = primary_dir(vec2(p) + 0.5);
    imageStore(out_image, ivec2(p), vec4(trace(frame.eye, dir), 1.0));
#ifdef COUNT_RAYS
    ray_count_buf.pixels[p.y * frame.width + p.x] = rays_traced;
#endif
}
