#include "apps/view/surface_view.h"

#include <epoxy/gl.h>

#include "apps/view/gl_program.h"

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


} // namespace

SurfaceView::SurfaceView(const std::vector<unsigned>& triangles, int vertexCount)
    : indexCount_(static_cast<int>(triangles.size())) {
  program_ = buildSurfaceProgram(kVertexShader);

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
