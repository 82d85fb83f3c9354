/*
 * Mesa 22.3's llvmpipe keeps a loop going while a SIMD lane that is no
 * invocation has not left it; such a lane reads storage buffers as zero, and
 * once the driver's 65,535 loop turns per vector are spent, every later loop
 * of the real invocations leaves after one turn. README.md (this folder) says
 * what it did to twinray and how to run this.
 *
 * Each invocation walks a list that ends at once (next[x] = 64 for every x),
 * then counts to `count` (10). With local_size_x = 4, llvmpipe runs each
 * workgroup as an 8-lane vector whose lanes 4-7 are no invocation: they read
 * next[i] as 0, so i stays 0 and the walk never ends for them, and every real
 * invocation counts to 1. With local_size_x = 8 all count to 10.
 */
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl31.h>
#include <stdio.h>
#include <stdlib.h>

static const char *source =
    "#version 310 es\n"
    "layout(local_size_x = %d) in;\n"
    "layout(std430, binding = 0) buffer B { uint count; uint next[64]; uint result[64]; };\n"
    "void main() {\n"
    "    uint x = gl_GlobalInvocationID.x;\n"
    "    uint i = x;\n"
    "    while (i < 64u) {\n"
    "        i = next[i];\n"
    "    }\n"
    "    uint n = 0u;\n"
    "    for (uint k = 0u; k < count; k++) {\n"
    "        n += 1u;\n"
    "    }\n"
    "    result[x] = n;\n"
    "}\n";

int main(int argc, char **argv) {
    int wg = argc > 1 ? atoi(argv[1]) : 4;
    if (wg < 1 || 64 % wg != 0) {
        fprintf(stderr, "repro: the workgroup width '%s' does not divide 64\n", argv[1]);
        return 2;
    }
    EGLDisplay display = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (!eglInitialize(display, NULL, NULL) || !eglBindAPI(EGL_OPENGL_ES_API)) {
        fprintf(stderr, "repro: no surfaceless EGL display\n");
        return 3;
    }
    EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 1, EGL_NONE};
    EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, context_attributes);
    if (context == EGL_NO_CONTEXT || !eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
        fprintf(stderr, "repro: no OpenGL ES 3.1 context\n");
        return 3;
    }
    printf("%s, local_size_x = %d\n", glGetString(GL_RENDERER), wg);

    char text[2048];
    snprintf(text, sizeof text, source, wg);
    const char *texts[] = {text};
    GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
    glShaderSource(shader, 1, texts, NULL);
    glCompileShader(shader);
    GLuint program = glCreateProgram();
    glAttachShader(program, shader);
    glLinkProgram(program);
    GLint linked;
    glGetProgramiv(program, GL_LINK_STATUS, &linked);
    if (!linked) {
        char log[4096];
        glGetProgramInfoLog(program, sizeof log, NULL, log);
        fprintf(stderr, "repro: %s\n", log);
        return 1;
    }

    GLuint data[1 + 64 + 64] = {10};
    for (int k = 0; k < 64; k++) {
        data[1 + k] = 64;
    }
    GLuint buffer;
    glGenBuffers(1, &buffer);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
    glBufferData(GL_SHADER_STORAGE_BUFFER, sizeof data, data, GL_DYNAMIC_READ);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffer);
    glUseProgram(program);
    glDispatchCompute(64 / wg, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    const GLuint *out = glMapBufferRange(GL_SHADER_STORAGE_BUFFER, 0, sizeof data, GL_MAP_READ_BIT);
    int wrong = 0;
    printf("result[0..7] =");
    for (int k = 0; k < 64; k++) {
        wrong += out[65 + k] != 10;
        if (k < 8) {
            printf(" %u", out[65 + k]);
        }
    }
    printf("\n%d of 64 invocations counted wrong (each should count to 10)\n", wrong);
    return wrong != 0;
}
