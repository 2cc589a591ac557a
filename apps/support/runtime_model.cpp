#include "apps/support/runtime_model.h"

#include <stdexcept>

#include "formats/mesh/read_mesh.h"
#include "formats/model/qvr.h"

namespace quiver::app {

RuntimeModel::RuntimeModel(const std::string& path) : path_(path) {
  char message[1024] = "";
  if (qv_model_load_file(path.c_str(), nullptr, nullptr, &model_, message, sizeof message) != QV_OK)
    throw std::runtime_error(message);
  qv_model_get_info(model_, &info_);
}

RuntimeModel::~RuntimeModel() { qv_model_destroy(model_); }

std::vector<unsigned> RuntimeModel::triangles() const {
  const unsigned* t = qv_model_triangles(model_);
  return std::vector<unsigned>(t, t + 3 * static_cast<size_t>(info_.triangle_count));
}

std::vector<unsigned> RuntimeModel::shownTriangles() const {
  if (!info_.render_vertex_count) return triangles();
  const unsigned* t = qv_model_render_triangles(model_);
  return std::vector<unsigned>(t, t + 3 * static_cast<size_t>(info_.render_triangle_count));
}

int RuntimeModel::shownVertexCount() const { return info_.render_vertex_count ? info_.render_vertex_count : info_.vertex_count; }

void RuntimeModel::positionsAt(const double* q, std::vector<float>& out) const {
  out.resize(3 * static_cast<size_t>(info_.vertex_count));
  qv_model_displacements(model_, q, out.data());
  const double* rest = qv_model_rest_positions(model_);
  for (size_t i = 0; i < out.size(); ++i) out[i] += static_cast<float>(rest[i]);
}

TetMesh RuntimeModel::mesh() const {
  // The runtime keeps no tets (it does not need them); the file has them.
  const std::string bytes = readFileBytes(path_);
  ModelView view;
  std::string error;
  if (!parseModel(bytes.data(), bytes.size(), view, error)) throw std::runtime_error(path_ + ": " + error);
  TetMesh mesh;
  for (uint32_t v = 0; v < view.info.vertexCount; ++v)
    mesh.vertices.emplace_back(view.restPositions[3 * v], view.restPositions[3 * v + 1], view.restPositions[3 * v + 2]);
  if (view.tets)
    for (uint32_t t = 0; t < view.info.tetCount; ++t)
      mesh.tets.push_back({int(view.tets[4 * t]), int(view.tets[4 * t + 1]), int(view.tets[4 * t + 2]), int(view.tets[4 * t + 3])});
  mesh.tetRegion.assign(mesh.tets.size(), 0);
  return mesh;
}

RuntimeModel::RenderBasis RuntimeModel::renderBasis() const {
  const std::string bytes = readFileBytes(path_);
  ModelView view;
  std::string error;
  if (!parseModel(bytes.data(), bytes.size(), view, error)) throw std::runtime_error(path_ + ": " + error);
  RenderBasis out;
  out.rows.assign(view.renderBasis, view.renderBasis + 3 * size_t(view.renderVertexCount) * view.info.r);
  if (view.rigidBody)
    for (int a = 0; a < 3; ++a) out.centre[a] = view.rigidBody[a];
  return out;
}

RuntimeInstance::RuntimeInstance(const RuntimeModel& model, const qv_instance_config& config)
    : model_(model.get()), config_(config), vertexCount_(static_cast<size_t>(model.info().vertex_count)) {
  if (qv_instance_create(model.get(), &config_, nullptr, &instance_) != QV_OK)
    throw std::runtime_error(config_.elasticity == QV_ELASTICITY_MODAL_WARPING && !model.info().has_modal_rotations
                                 ? model.path() + " has no modal rotations (bake it again for modal warping)"
                             : config_.free_flight && !model.info().has_rigid_body
                                 ? model.path() + " was baked with fixed vertices: only a model baked free (no --fix) can fly"
                             : config_.soft_contacts && (!config_.free_flight || config_.integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES ||
                                                         config_.elasticity == QV_ELASTICITY_MODAL_WARPING)
                                 ? "--soft-contacts needs --free, an implicit integrator (newmark or euler) and no modal warping"
                                 : "invalid simulation settings (time step, Newton iterations, damping)");
}

RuntimeInstance::~RuntimeInstance() { qv_instance_destroy(instance_); }

std::vector<float> RuntimeInstance::positions() const {
  std::vector<float> p(3 * vertexCount_);
  qv_instance_positions(instance_, p.data());
  return p;
}

std::vector<float> RuntimeInstance::shownPositions() const {
  qv_model_info info;
  qv_model_get_info(model_, &info);
  if (!info.render_vertex_count) return positions();
  std::vector<float> p(3 * static_cast<size_t>(info.render_vertex_count));
  scratch_.resize(qv_model_render_scratch_size(model_) / sizeof(double) + 1);
  qv_instance_render(instance_, p.data(), nullptr, scratch_.data());
  return p;
}

} // namespace quiver::app
