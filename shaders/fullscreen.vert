#version 450
// fullscreen.vert — one triangle that covers the viewport, generated from the
// vertex index, so no vertex buffer is needed in either API. (Two triangles
// that cover it exactly took as long: docs/findings/fragment-gap.md.)

void main() {
    int i = int(gl_VertexIndex);
    vec2 p = vec2(float((i << 1) & 2), float(i & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
