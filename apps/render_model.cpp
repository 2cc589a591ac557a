// `quiver render`: headless pictures of a model, drawn by the software rasterizer: the rest shape,
// the shape after pulling a vertex group for some steps, or a grid of the first basis vectors.
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "apps/render/software_renderer.h"
#include "apps/sim_scenario.h"
#include "quiver/quiver.h"

namespace quiver::app {

namespace {

constexpr std::array<uint8_t, 3> kWhite{255, 255, 255}, kSteel{70, 130, 180};

struct Loaded {
  qv_model* model = nullptr;
  qv_instance* instance = nullptr;
  qv_model_info info{};
  explicit Loaded(const std::string& path) {
    char message[1024] = "";
    if (qv_model_load_file(path.c_str(), nullptr, nullptr, &model, message, sizeof message) != QV_OK)
      throw std::runtime_error(message);
    qv_model_get_info(model, &info);
    qv_instance_config config;
    qv_instance_config_init(&config, model);
    config.newton_iterations = 2;
    if (qv_instance_create(model, &config, nullptr, &instance) != QV_OK) throw std::runtime_error("cannot create an instance");
  }
  ~Loaded() {
    qv_instance_destroy(instance);
    qv_model_destroy(model);
  }
  std::vector<float> positions() const {
    std::vector<float> p(3 * static_cast<size_t>(info.vertex_count));
    qv_instance_positions(instance, p.data());
    return p;
  }
  std::vector<unsigned> triangles() const {
    const unsigned* t = qv_model_triangles(model);
    return std::vector<unsigned>(t, t + 3 * static_cast<size_t>(info.triangle_count));
  }
};

// The box the pictures frame: the rest box grown by `margin` of its diagonal on every side, so that
// deformed shapes stay in view and every picture of one model shares one camera.
Camera camera(const qv_model_info& info, int width, int height, double margin) {
  const Eigen::Vector3d lo(info.bbox_min), hi(info.bbox_max);
  const double grow = margin * (hi - lo).norm();
  return Camera::framing(lo.array() - grow, hi.array() + grow, width, height);
}

} // namespace

void RenderOptions::addTo(CLI::App& app) {
  app.add_option("-o,--output", output, "PNG file to write")->required();
  app.add_option("--size", size, "Width,height in pixels")->delimiter(',')->expected(2)->capture_default_str();
  app.add_option("--modes", modes, "Draw a grid of the first N basis vectors instead of one shape");
  app.add_option("--amplitude", amplitude, "Grid: largest displacement of each basis vector, as a fraction of the model's size")
      ->capture_default_str();
  app.add_option("--pull", pull, "Pull the --group with this total force (N, fx,fy,fz) for --steps steps, then draw")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--group", group, "Vertices to pull, a selector such as \"x>max-1e-6\"")->capture_default_str();
  app.add_option("--steps", steps, "Steps of the pull")->capture_default_str();
}

int renderModel(const std::string& path, const RenderOptions& o) {
  if (o.size.size() != 2 || o.size[0] < 16 || o.size[1] < 16 || o.size[0] > 8192 || o.size[1] > 8192)
    throw std::runtime_error("--size must be two numbers between 16 and 8192");
  Loaded m(path);
  const std::vector<unsigned> triangles = m.triangles();
  const int width = o.size[0], height = o.size[1];
  Image image(width, height);
  image.clear(kWhite);
  if (o.modes > 0) {
    const int n = std::min(o.modes, m.info.r), columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
    const int rows = (n + columns - 1) / columns, tileW = width / columns, tileH = height / rows;
    const Camera cam = camera(m.info, tileW, tileH, o.amplitude);
    const double size = Eigen::Vector3d(Eigen::Vector3d(m.info.bbox_max) - Eigen::Vector3d(m.info.bbox_min)).norm();
    std::vector<double> q(m.info.r, 0.0);
    std::vector<float> u(3 * static_cast<size_t>(m.info.vertex_count));
    for (int j = 0; j < n; ++j) {
      std::fill(q.begin(), q.end(), 0.0);
      q[j] = 1;
      qv_model_displacements(m.model, q.data(), u.data());
      float largest = 0;
      for (float x : u) largest = std::max(largest, std::abs(x));
      q[j] = largest > 0 ? o.amplitude * size / largest : 0;
      qv_instance_set_state(m.instance, q.data(), nullptr, nullptr);
      Image tile(tileW, tileH);
      tile.clear(kWhite);
      drawTriangles(tile, cam, m.positions(), triangles, kSteel);
      image.paste(tile, (j % columns) * tileW, (j / columns) * tileH);
    }
  } else {
    if (o.pull != std::vector<double>{0, 0, 0}) {
      const double* rest = qv_model_rest_positions(m.model);
      TetMesh points;
      for (int v = 0; v < m.info.vertex_count; ++v) points.vertices.emplace_back(rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]);
      const std::vector<int> group = selectGroup(points, o.group);
      const double share[3] = {o.pull[0] / group.size(), o.pull[1] / group.size(), o.pull[2] / group.size()};
      int resets = 0;
      for (int step = 0; step < o.steps; ++step) {
        for (int v : group) qv_instance_add_vertex_force(m.instance, v, share);
        resets += qv_instance_step(m.instance) == QV_STEP_RESET;
      }
      // The runtime resets a diverged state to rest; say so rather than draw a rest shape as "pulled".
      if (resets > 0)
        std::fprintf(stderr, "quiver render: warning: the pull diverged and the model was reset to rest %d times; "
                             "try a smaller --pull\n", resets);
    }
    drawTriangles(image, camera(m.info, width, height, 0.15), m.positions(), triangles, kSteel);
  }
  writePng(o.output, image);
  return 0;
}

} // namespace quiver::app
