// A C++ program on the installed runtime: RAII over the C API, one object pushed for a second.
//   consumer_cpp MODEL.qvr
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <quiver/quiver.h>

int main(int argc, char** argv) {
  if (argc != 2 || !QV_CHECK_VERSION()) return 2;
  qv_model* raw = nullptr;
  char message[512];
  if (qv_model_load_file(argv[1], nullptr, nullptr, &raw, message, sizeof message) != QV_OK) {
    std::fprintf(stderr, "consumer_cpp: %s\n", message);
    return 1;
  }
  std::unique_ptr<qv_model, decltype(&qv_model_destroy)> model(raw, qv_model_destroy);
  qv_model_info info;
  qv_model_get_info(model.get(), &info);
  qv_instance_config config;
  qv_instance_config_init(&config, model.get());
  qv_instance* object = nullptr;
  if (qv_instance_create(model.get(), &config, nullptr, &object) != QV_OK) return 1;
  std::unique_ptr<qv_instance, decltype(&qv_instance_destroy)> instance(object, qv_instance_destroy);
  const double push[3] = {0, 0, -1};
  std::vector<float> positions(3 * static_cast<size_t>(info.vertex_count));
  for (int frame = 0; frame < 60; ++frame) {
    qv_instance_add_vertex_force(instance.get(), info.vertex_count - 1, push);
    if (qv_instance_step(instance.get()) == QV_STEP_RESET) return 1;
  }
  qv_instance_positions(instance.get(), positions.data());
  const double* rest = qv_model_rest_positions(model.get());
  double moved = 0;
  for (size_t i = 0; i < positions.size(); ++i) moved = std::fmax(moved, std::fabs(positions[i] - rest[i]));
  std::printf("quiver %s from C++: r = %d, largest displacement after 1 s %.3g m\n", qv_version_string(), info.r, moved);
  return moved > 0 && std::isfinite(moved) ? 0 : 1;
}
