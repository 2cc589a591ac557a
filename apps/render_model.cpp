// `quiver render`: headless pictures of a model, drawn by the software rasterizer: the rest shape,
// the shape a scenario leaves (or its whole run, animated), or a grid of the first linear modes
// (or basis vectors), still or oscillating.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "apps/render/collider_mesh.h"
#include "apps/render/frame_writer.h"
#include "apps/render/software_renderer.h"
#include "apps/runtime_target.h"
#include "apps/sim_scenario.h"
#include "apps/support/mesh_options.h"
#include "apps/support/reduced_modes.h"

namespace quiver::app {

namespace {

constexpr std::array<uint8_t, 3> kWhite{255, 255, 255}, kSteel{70, 130, 180}, kStone{200, 196, 188};
constexpr int kFramesPerOscillation = 30;

// The box the pictures frame: the rest box grown by `margin` of its diagonal on every side, so that
// deformed shapes stay in view and every picture of one model shares one camera.
Camera camera(const qv_model_info& info, int width, int height, double margin) {
  const Eigen::Vector3d lo(info.bbox_min), hi(info.bbox_max);
  const double grow = margin * (hi - lo).norm();
  return Camera::framing(lo.array() - grow, hi.array() + grow, width, height);
}

Image picture(const Camera& cam, int width, int height, const std::vector<float>& positions,
              const std::vector<unsigned>& triangles) {
  Image image(width, height);
  image.clear(kWhite);
  drawTriangles(image, cam, positions, triangles, kSteel);
  return image;
}

// Free flight: runs the scenario keeping the frames, then draws them with the colliders under one
// camera that frames the whole flight (the object leaves its rest box).
void renderFlight(const RuntimeModel& model, const RenderOptions& o, int width, int height) {
  RuntimeTarget target(model, o.scenario.step);
  FrameWriter frames(o.output, o.every * target.timeStep());
  std::vector<std::vector<float>> shots;  // all bodies' positions, one after the other
  const auto keep = [&] {
    std::vector<float> all;
    for (int k = 0; k < target.flight()->bodyCount(); ++k) {
      const std::vector<float> p = target.flight()->body(k).shownPositions();
      all.insert(all.end(), p.begin(), p.end());
    }
    shots.push_back(std::move(all));
  };
  runScenario(target, model.mesh(), o.scenario, [&](int step) {
    if (frames.animated() ? step % o.every == 0 : step == o.scenario.steps) keep();
  });
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const auto& p : shots)
    for (size_t v = 0; v < p.size() / 3; ++v)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], double(p[3 * v + a])), hi[a] = std::max(hi[a], double(p[3 * v + a]));
  const Eigen::Vector3d grow = Eigen::Vector3d::Constant(0.1 * (hi - lo).norm());
  TriangleSoup world;
  const ColliderSet& colliders = target.flight()->colliders();
  for (int k = 0; k < colliders.size(); ++k) appendCollider(colliders[k], colliders.surface(k), lo, hi, world);
  const Camera cam = Camera::framing(lo - grow, hi + grow, width, height);
  std::vector<unsigned> triangles;
  const std::vector<unsigned> one = model.shownTriangles();
  for (int k = 0; k < target.flight()->bodyCount(); ++k)
    for (unsigned index : one) triangles.push_back(index + static_cast<unsigned>(k * model.shownVertexCount()));
  for (const auto& p : shots) {
    Image image(width, height);
    image.clear(kWhite);
    drawTriangles(image, cam, world.positions, world.triangles, kStone);
    drawTriangles(image, cam, p, triangles, kSteel);
    frames.add(image);
  }
  frames.finish();
}

// Grid of the first `count` linear modes (or basis vectors), each scaled so that its largest vertex
// displacement is `amplitude` of the model's diagonal, then by `phase` in [-1, 1].
class ModeGrid {
public:
  ModeGrid(const RuntimeModel& model, const RenderOptions& o) : model_(model), o_(o), triangles_(model.triangles()) {
    const qv_model_info& info = model.info();
    count_ = std::min(o.modes, info.r);
    columns_ = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count_))));
    const int rows = (count_ + columns_ - 1) / columns_;
    tileW_ = o.size[0] / columns_;
    tileH_ = o.size[1] / rows;
    camera_ = camera(info, tileW_, tileH_, o.amplitude);
    const Eigen::MatrixXd directions =
        o.basis ? Eigen::MatrixXd::Identity(info.r, info.r) : reducedModes(model.get()).vectors;
    const double size = (Eigen::Vector3d(info.bbox_max) - Eigen::Vector3d(info.bbox_min)).norm();
    for (int j = 0; j < count_; ++j)
      shapes_.push_back(withLargestDisplacement(model.get(), directions.col(j), o.amplitude * size));
  }

  Image draw(double phase) const {
    std::vector<float> x;
    Image image(o_.size[0], o_.size[1]);
    image.clear(kWhite);
    for (int j = 0; j < count_; ++j) {
      const Eigen::VectorXd q = phase * shapes_[j];
      model_.positionsAt(q.data(), x);
      image.paste(picture(camera_, tileW_, tileH_, x, triangles_), (j % columns_) * tileW_, (j / columns_) * tileH_);
    }
    return image;
  }

private:
  const RuntimeModel& model_;
  const RenderOptions& o_;
  std::vector<unsigned> triangles_;
  int count_, columns_, tileW_, tileH_;
  Camera camera_;
  std::vector<Eigen::VectorXd> shapes_;
};

} // namespace

void RenderOptions::addTo(CLI::App& app) {
  app.add_option("-o,--output", output, "NAME.png (one picture), NAME.gif (animated) or NAME_%04d.png (image sequence)")
      ->required();
  app.add_option("--size", size, "Width,height in pixels")->delimiter(',')->expected(2)->capture_default_str();
  app.add_option("--modes", modes, "Draw a grid of the first N linear modes instead of one shape (animated: oscillating)")
      ->check(Positive);
  app.add_flag("--basis", basis, "The grid shows the first N basis vectors (columns of U) instead of linear modes");
  app.add_option("--amplitude", amplitude, "Grid: largest displacement of each mode, as a fraction of the model's size")
      ->capture_default_str();
  app.add_option("--every", every, "Animated scenario: a frame every k-th step")
      ->capture_default_str()
      ->check(Positive);
  scenario.addScenarioTo(app);
  addSolverOption(app, scenario.step.solver);
}

int renderModel(const std::string& path, const RenderOptions& o) {
  if (o.size.size() != 2 || o.size[0] < 16 || o.size[1] < 16 || o.size[0] > 8192 || o.size[1] > 8192)
    throw std::runtime_error("--size must be two numbers between 16 and 8192");
  if (!(o.amplitude > 0 && o.amplitude <= 1)) throw std::runtime_error("--amplitude must be above 0 and at most 1");
  const RuntimeModel model(path);
  const int width = o.size[0], height = o.size[1];
  if (o.modes > 0) {
    if (o.scenario.hasLoad()) throw std::runtime_error("--modes draws the modes alone: drop the scenario's loads");
    if (o.modes > model.info().r)
      std::fprintf(stderr, "quiver render: warning: --modes %d: the model has r = %d, so %d are drawn\n", o.modes,
                   model.info().r, model.info().r);
    const ModeGrid grid(model, o);
    FrameWriter frames(o.output, 1.0 / kFramesPerOscillation);
    if (!frames.animated()) frames.add(grid.draw(1));
    for (int f = 0; frames.animated() && f < kFramesPerOscillation; ++f)
      frames.add(grid.draw(std::sin(2 * M_PI * f / kFramesPerOscillation)));
    frames.finish();
    return 0;
  }
  if (o.scenario.step.freeFlight) {
    renderFlight(model, o, width, height);
    return 0;
  }
  RuntimeTarget target(model, o.scenario.step);
  FrameWriter frames(o.output, o.every * target.timeStep());
  const Camera cam = camera(model.info(), width, height, 0.15);
  const std::vector<unsigned> triangles = model.shownTriangles();  // the render mesh when it has one
  const auto draw = [&] { frames.add(picture(cam, width, height, target.instance().shownPositions(), triangles)); };
  if (!o.scenario.hasLoad()) {
    if (frames.animated()) throw std::runtime_error("nothing moves: give a scenario (--force, --drag, --twist, --gravity) or --modes");
    draw();
  } else {
    const ScenarioResult result = runScenario(target, model.mesh(), o.scenario, [&](int step) {
      if (frames.animated() ? step % o.every == 0 : step == o.scenario.steps) draw();
    });
    // The runtime resets a non-finite state to rest; say so rather than show a rest shape as "loaded".
    if (result.failedSteps > 0)
      std::fprintf(stderr, "quiver render: warning: the scenario went non-finite and the model was reset to rest %d "
                           "times\n", result.failedSteps);
  }
  frames.finish();
  return 0;
}

} // namespace quiver::app
