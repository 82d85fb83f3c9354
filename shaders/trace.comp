// trace.comp — compute entry point: the same tracer, one invocation per pixel,
// written to an RGBA32F storage image instead of a colour attachment.
//
// Pixel (x, y) is the invocation's place in its workgroup's tile, with y counted
// from the top (the tile comes from the launch order, below), and the
// primary ray goes through its centre, (x, y) + 0.5: exactly the gl_FragCoord
// the fragment path sees in Vulkan. Image row 0 is therefore the top row in both
// APIs, and a plain copy/readback of the image gives the upright picture.
//
// WG_X x WG_Y is the workgroup size, set per run through naga defines
// (common/src/shader/build.rs); the dispatch is ceil(width / WG_X) x ceil(height / WG_Y)
// tiles, so invocations past the right and bottom edges return at once.
//
// Which tile a workgroup traces comes from the launch order (binding 8,
// common/src/plan/launch.rs): a GPU starts workgroups in about the order of
// their index, and a frame lasts until its slowest last ones finish, so the
// costliest tiles are listed first, and those that see nothing are flagged.
// The frame says which grid of tiles the order was made for: without one (a
// window, whose camera moves and whose size changes) or for another grid, the
// tiles go in rows, and no workgroup waits on a load before its first ray.

#ifndef WG_X
#define WG_X 8
#endif
#ifndef WG_Y
#define WG_Y 4
#endif

layout(local_size_x = WG_X, local_size_y = WG_Y, local_size_z = 1) in;

layout(rgba32f, set = 0, binding = 5) uniform writeonly image2D out_image;

// Each workgroup's tile, y * tiles across + x, in launch order.
layout(std430, set = 0, binding = 8) readonly buffer LaunchOrder {
    uint tiles[];
} launch_buf;

// A tile flagged in the launch order (common/src/plan/launch.rs, EMPTY_TILE):
// every pixel's primary ray misses every box of the tree's root's children,
// so the pixel is the background, which the walk would have returned after
// its first node step. Its workgroup stores that and is done.
const uint EMPTY_TILE = 0x80000000u;

#ifdef SHARED_PAD_KIB
// --shared-pad (a measurement): workgroup memory the tracer does not need. A
// driver splits each multiprocessor's memory between shared memory and L1
// cache by what its shaders declare, and fits fewer workgroups once shared
// memory runs out; this shows what either does to the time. Each invocation
// writes one word, spread across the whole array, and reads it back through an
// index the compiler cannot prove equal (the dispatch's depth is always 1), so no
// compiler can drop the array, and no invocation reads another's word.
shared uint shared_pad[SHARED_PAD_KIB * 256];
#endif

void main() {
#ifdef SHARED_PAD_KIB
    uint group = uint(WG_X * WG_Y);
    uint stride = uint(SHARED_PAD_KIB * 256) / group;
    shared_pad[gl_LocalInvocationIndex * stride] = gl_LocalInvocationIndex;
    if (shared_pad[((gl_LocalInvocationIndex + gl_NumWorkGroups.z - 1u) % group) * stride] == 0xffffffffu) {
        return;
    }
#endif
    uvec2 groups = gl_NumWorkGroups.xy;
    uvec2 tile = gl_WorkGroupID.xy;
    bool empty = false;
    if (frame.launch_grid == ((groups.x << 16u) | groups.y)) {
        uint t = launch_buf.tiles[tile.y * groups.x + tile.x];
        empty = (t & EMPTY_TILE) != 0u;
        t &= ~EMPTY_TILE;
        tile = uvec2(t % groups.x, t / groups.x);
    }
    uvec2 p = tile * uvec2(WG_X, WG_Y) + gl_LocalInvocationID.xy;
    if (p.x >= frame.width || p.y >= frame.height) {
        return;
    }
#ifdef COUNT_RAYS
    rays_traced = RayCount(1u, 0u, 0u, 0u, 0u);
#endif
    if (empty) {
        // trace()'s colour for a ray that hits nothing: 0 + 1 * background.
        imageStore(out_image, ivec2(p), vec4(frame.background, 1.0));
#ifdef COUNT_RAYS
        ray_count_buf.pixels[p.y * frame.width + p.x] = rays_traced;
#endif
        return;
    }
    vec3 dir = primary_dir(vec2(p) + 0.5);
    imageStore(out_image, ivec2(p), vec4(trace(frame.eye, dir), 1.0));
#ifdef COUNT_RAYS
    ray_count_buf.pixels[p.y * frame.width + p.x] = rays_traced;
#endif
}
