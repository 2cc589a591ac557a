#include "apps/view/render_basis_view.h"


#include <epoxy/gl.h>

#include "apps/view/gl_program.h"

namespace quiver::app {

namespace {

// q as a uniform array: at most the 256 basis vectors a .qvr may have (GL 3.3 guarantees 1024
// vertex uniform components).
const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 rest;
uniform samplerBuffer basis;  // 3 r floats per vertex
uniform int r;
uniform float q[256];
uniform mat4 bodyToWorld;
uniform mat4 view;
uniform mat4 projection;
out vec3 viewPosition;
out vec3 viewNormal;  // unused: shaded flat
void main() {
  vec3 u = vec3(0.0);
  int row = 3 * r * gl_VertexID;
  for (int j = 0; j < r; ++j)
    u += q[j] * vec3(texelFetch(basis, row + j).r, texelFetch(basis, row + r + j).r, texelFetch(basis, row + 2 * r + j).r);
  vec4 p = view * (bodyToWorld * vec4(rest + u, 1.0));
  viewPosition = p.xyz;
  viewNormal = vec3(0.0, 0.0, 1.0);
  gl_Position = projection * p;
}
)";


} // namespace

RenderBasisView::RenderBasisView(const std::vector<float>& rest, const std::vector<unsigned>& triangles,
                                 const std::vector<float>& rows, int r)
    : indexCount_(static_cast<int>(triangles.size())), r_(r) {
  program_ = buildSurfaceProgram(kVertexShader);
  glGenVertexArrays(1, &array_);
  glBindVertexArray(array_);
  glGenBuffers(1, &rest_);
  glBindBuffer(GL_ARRAY_BUFFER, rest_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(rest.size() * sizeof(float)), rest.data(), GL_STATIC_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);
  glGenBuffers(1, &indices_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, indices_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(triangles.size() * sizeof(unsigned)), triangles.data(),
               GL_STATIC_DRAW);
  glBindVertexArray(0);
  glGenBuffers(1, &basisBuffer_);
  glBindBuffer(GL_TEXTURE_BUFFER, basisBuffer_);
  glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(rows.size() * sizeof(float)), rows.data(), GL_STATIC_DRAW);
  glGenTextures(1, &basisTexture_);
  glBindTexture(GL_TEXTURE_BUFFER, basisTexture_);
  glTexBuffer(GL_TEXTURE_BUFFER, GL_R32F, basisBuffer_);
  glBindTexture(GL_TEXTURE_BUFFER, 0);
}

RenderBasisView::~RenderBasisView() {
  const unsigned buffers[] = {rest_, indices_, basisBuffer_};
  glDeleteBuffers(3, buffers);
  glDeleteTextures(1, &basisTexture_);
  glDeleteVertexArrays(1, &array_);
  glDeleteProgram(program_);
}

void RenderBasisView::draw(const Eigen::Matrix4f& view, const Eigen::Matrix4f& projection, const Eigen::Vector3f& colour,
                           const std::vector<double>& q, const Eigen::Matrix4f& bodyToWorld) const {
  std::vector<float> qf(q.begin(), q.end());
  glUseProgram(program_);
  glUniformMatrix4fv(glGetUniformLocation(program_, "view"), 1, GL_FALSE, view.data());
  glUniformMatrix4fv(glGetUniformLocation(program_, "projection"), 1, GL_FALSE, projection.data());
  glUniformMatrix4fv(glGetUniformLocation(program_, "bodyToWorld"), 1, GL_FALSE, bodyToWorld.data());
  glUniform3fv(glGetUniformLocation(program_, "colour"), 1, colour.data());
  glUniform1i(glGetUniformLocation(program_, "lit"), 1);
  glUniform1i(glGetUniformLocation(program_, "smoothNormals"), 0);
  glUniform1i(glGetUniformLocation(program_, "r"), r_);
  glUniform1fv(glGetUniformLocation(program_, "q"), r_, qf.data());
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_BUFFER, basisTexture_);
  glUniform1i(glGetUniformLocation(program_, "basis"), 0);
  glEnable(GL_DEPTH_TEST);
  glBindVertexArray(array_);
  glDrawElements(GL_TRIANGLES, indexCount_, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glBindTexture(GL_TEXTURE_BUFFER, 0);
}

} // namespace quiver::app
