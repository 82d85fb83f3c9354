#version 450
// fullscreen.vert — one triangle that covers the viewport, generated from the
// vertex index, so no vertex buffer is needed in either API.
// FULLSCREEN_QUAD (--experiment quad): two triangles that cover it exactly
// (6 vertices), to measure what the oversized triangle's clipping costs.

void main() {
    int i = int(gl_VertexIndex);
#ifdef FULLSCREEN_QUAD
    // Corners 0..3 of the unit square (x = bit 0, y = bit 1): triangles 0,1,2
    // and 3,2,1, both wound the same way.
    int c = i < 3 ? i : 6 - i;
    vec2 p = vec2(float(c & 1), float(c >> 1));
#else
    vec2 p = vec2(float((i << 1) & 2), float(i & 2));
#endif
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
