#pragma once
// A .qvr model and an instance of it, loaded through the runtime's C API and owned the C++ way, for
// the tools: the C API reports failures through a message buffer, the tools throw that message.
#include <string>
#include <vector>

#include "common/tet_mesh.h"
#include "quiver/quiver.h"

namespace quiver::app {

class RuntimeModel {
public:
  explicit RuntimeModel(const std::string& path);  // throws the loader's message (file, section, offset)
  ~RuntimeModel();
  RuntimeModel(const RuntimeModel&) = delete;
  RuntimeModel& operator=(const RuntimeModel&) = delete;

  const qv_model* get() const { return model_; }
  const qv_model_info& info() const { return info_; }
  const std::string& path() const { return path_; }
  std::vector<unsigned> triangles() const;
  // What the tools draw: the render mesh when the model has one, else the tets' surface (all
  // vertices, those off the surface unused). shownVertexCount() positions go with them.
  std::vector<unsigned> shownTriangles() const;
  int shownVertexCount() const;
  // Positions X + U q (3 floats per vertex) of reduced coordinates `q` (r values), without an instance.
  void positionsAt(const double* q, std::vector<float>& out) const;
  // Rest shape and tets, for vertex selection and .vtu frames.
  TetMesh mesh() const;
  // The render mesh's basis rows W U (3 x r floats per render vertex), which the runtime does not
  // keep, from the file, for drawing on the GPU; and a free model's centre of mass as baked.
  struct RenderBasis {
    std::vector<float> rows;
    double centre[3] = {0, 0, 0};
  };
  RenderBasis renderBasis() const;

private:
  std::string path_;
  qv_model* model_ = nullptr;
  qv_model_info info_{};
};

class RuntimeInstance {
public:
  // Throws naming what is wrong with `config` (or that the model cannot do modal warping).
  RuntimeInstance(const RuntimeModel& model, const qv_instance_config& config);
  ~RuntimeInstance();
  RuntimeInstance(const RuntimeInstance&) = delete;
  RuntimeInstance& operator=(const RuntimeInstance&) = delete;

  qv_instance* get() const { return instance_; }
  const qv_instance_config& config() const { return config_; }
  std::vector<float> positions() const;  // 3 per vertex
  // The render mesh's positions (qv_instance_render) when the model has one, else positions().
  std::vector<float> shownPositions() const;

private:
  qv_instance* instance_ = nullptr;
  const qv_model* model_ = nullptr;
  mutable std::vector<double> scratch_;  // qv_instance_render's
  qv_instance_config config_;
  size_t vertexCount_;
};

} // namespace quiver::app
