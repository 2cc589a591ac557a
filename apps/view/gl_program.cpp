#include "apps/view/gl_program.h"

#include <stdexcept>
#include <string>

#include <epoxy/gl.h>

namespace quiver::app {

namespace {

const char* kFragmentShader = R"(#version 330 core
in vec3 viewNormal;
in vec3 viewPosition;
uniform vec3 colour;
uniform int lit;
uniform int smoothNormals;
out vec4 fragment;
void main() {
  if (lit == 0) { fragment = vec4(colour, 1.0); return; }
  vec3 toEye = normalize(-viewPosition);
  // Flat: the triangle's own normal, from screen-space derivatives; the edges of a coarse tet mesh stay sharp.
  vec3 n = smoothNormals != 0 ? normalize(viewNormal) : normalize(cross(dFdx(viewPosition), dFdy(viewPosition)));
  if (dot(n, toEye) < 0.0) n = -n;  // two-sided: inner faces show when the surface folds
  vec3 key = normalize(vec3(-0.4, 0.8, 0.6));
  float diffuse = 0.55 * max(dot(n, toEye), 0.0) + 0.35 * max(dot(n, key), 0.0);
  float specular = 0.25 * pow(max(dot(n, normalize(key + toEye)), 0.0), 40.0);
  fragment = vec4(colour * (0.22 + diffuse) + vec3(specular), 1.0);
}
)";

unsigned compile(GLenum kind, const char* source) {
  const unsigned shader = glCreateShader(kind);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  int ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = "";
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    throw std::runtime_error(std::string("OpenGL shader does not compile: ") + log);
  }
  return shader;
}

} // namespace

unsigned buildSurfaceProgram(const char* vertexShader) {
  const unsigned vs = compile(GL_VERTEX_SHADER, vertexShader), fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  const unsigned program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  int ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    glDeleteProgram(program);
    throw std::runtime_error("OpenGL shader program does not link");
  }
  return program;
}

} // namespace quiver::app
