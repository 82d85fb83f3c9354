// trace.frag — fullscreen fragment entry point: one primary ray per pixel centre.
// gl_FragCoord has +y down in Vulkan and +y up in OpenGL; glReadPixels returns
// bottom-up rows, so treating y as "down" yields the same upright image in both.

layout(location = 0) out vec4 out_color;

void main() {
    vec3 dir = primary_dir(gl_FragCoord.xy);
    out_color = vec4(trace(frame.eye, dir), 1.0);
}
