#include "apps/view/surface_view.h"

#include <stdexcept>
#include <string>

#include <epoxy/gl.h>

namespace quiver::app {

namespace {

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 view;
uniform mat4 projection;
out vec3 viewNormal;
out vec3 viewPosition;
void main() {
  vec4 p = view * vec4(position, 1.0);
  viewPosition = p.xyz;
  viewNormal = mat3(view) * normal;
  gl_Position = projection * p;
}
)";

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

SurfaceView::SurfaceView(const std::vector<unsigned>& triangles, int vertexCount)
    : indexCount_(static_cast<int>(triangles.size())) {
  const unsigned vs = compile(GL_VERTEX_SHADER, kVertexShader), fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  program_ = glCreateProgram();
  glAttachShader(program_, vs);
  glAttachShader(program_, fs);
  glLinkProgram(program_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  int ok = 0;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (!ok) throw std::runtime_error("OpenGL shader program does not link");

  const GLsizeiptr bytes = 3 * static_cast<GLsizeiptr>(vertexCount) * sizeof(float);
  glGenVertexArrays(1, &surfaceArray_);
  glBindVertexArray(surfaceArray_);
  glGenBuffers(1, &positions_);
  glBindBuffer(GL_ARRAY_BUFFER, positions_);
  glBufferData(GL_ARRAY_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);
  glGenBuffers(1, &normals_);
  glBindBuffer(GL_ARRAY_BUFFER, normals_);
  glBufferData(GL_ARRAY_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(1);
  glGenBuffers(1, &indices_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, indices_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(triangles.size() * sizeof(unsigned)), triangles.data(),
               GL_STATIC_DRAW);

  glGenVertexArrays(1, &lineArray_);
  glBindVertexArray(lineArray_);
  glGenBuffers(1, &linePoints_);
  glBindBuffer(GL_ARRAY_BUFFER, linePoints_);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);
  glVertexAttrib3f(1, 0, 0, 1);
  glBindVertexArray(0);
}

SurfaceView::~SurfaceView() {
  const unsigned buffers[] = {positions_, normals_, indices_, linePoints_}, arrays[] = {surfaceArray_, lineArray_};
  glDeleteBuffers(4, buffers);
  glDeleteVertexArrays(2, arrays);
  glDeleteProgram(program_);
}

void SurfaceView::update(const std::vector<float>& positions, const std::vector<float>& normals) {
  glBindBuffer(GL_ARRAY_BUFFER, positions_);
  glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(positions.size() * sizeof(float)), positions.data());
  glBindBuffer(GL_ARRAY_BUFFER, normals_);
  glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(normals.size() * sizeof(float)), normals.data());
}

void SurfaceView::draw(const Eigen::Matrix4f& view, const Eigen::Matrix4f& projection, const Eigen::Vector3f& colour,
                       bool smoothNormals) const {
  glUseProgram(program_);
  glUniformMatrix4fv(glGetUniformLocation(program_, "view"), 1, GL_FALSE, view.data());  // Eigen is column-major, as GL
  glUniformMatrix4fv(glGetUniformLocation(program_, "projection"), 1, GL_FALSE, projection.data());
  glUniform3fv(glGetUniformLocation(program_, "colour"), 1, colour.data());
  glUniform1i(glGetUniformLocation(program_, "lit"), 1);
  glUniform1i(glGetUniformLocation(program_, "smoothNormals"), smoothNormals);
  glEnable(GL_DEPTH_TEST);
  glBindVertexArray(surfaceArray_);
  glDrawElements(GL_TRIANGLES, indexCount_, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

void SurfaceView::drawLines(const std::vector<float>& points, const Eigen::Matrix4f& view,
                            const Eigen::Matrix4f& projection, const Eigen::Vector3f& colour) const {
  glUseProgram(program_);
  glUniformMatrix4fv(glGetUniformLocation(program_, "view"), 1, GL_FALSE, view.data());
  glUniformMatrix4fv(glGetUniformLocation(program_, "projection"), 1, GL_FALSE, projection.data());
  glUniform3fv(glGetUniformLocation(program_, "colour"), 1, colour.data());
  glUniform1i(glGetUniformLocation(program_, "lit"), 0);
  glDisable(GL_DEPTH_TEST);  // overlays stay visible through the surface
  glBindVertexArray(lineArray_);
  glBindBuffer(GL_ARRAY_BUFFER, linePoints_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(points.size() * sizeof(float)), points.data(), GL_STREAM_DRAW);
  glDrawArrays(GL_LINES, 0, static_cast<int>(points.size() / 3));
  glBindVertexArray(0);
}

} // namespace quiver::app
