#pragma once
// The viewer's one surface shading (two-sided Blinn-Phong, a headlight and a key light; flat from
// screen-space derivatives or smooth from the vertex normals) linked with a vertex shader of the
// caller's, which writes `viewPosition` and `viewNormal`. Uniforms: colour, lit, smoothNormals.
namespace quiver::app {

// The linked program; throws naming the compiler's message. Needs a current GL context.
unsigned buildSurfaceProgram(const char* vertexShader);

} // namespace quiver::app
