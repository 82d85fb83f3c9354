// trace.frag — fullscreen fragment entry point: one primary ray per pixel centre.
// gl_FragCoord has +y down in Vulkan and +y up in OpenGL; glReadPixels returns
// bottom-up rows, so treating y as "down" yields the same upright image in both.

layout(location = 0) out vec4 out_color;

void main() {
#ifdef COUNT_RAYS
    rays_traced = RayCount(1u, 0u, 0u, 0u, 0u);
#endif
    vec3 dir = primary_dir(gl_FragCoord.xy);
    out_color = vec4(trace(frame.eye, dir), 1.0);
#ifdef COUNT_RAYS
    uvec2 p = uvec2(gl_FragCoord.xy);
    ray_count_buf.pixels[p.y * frame.width + p.x] = rays_traced;
#endif
}
