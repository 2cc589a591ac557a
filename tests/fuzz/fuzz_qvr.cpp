// libFuzzer target for the .qvr reader, under AddressSanitizer and UBSan. Each input is parsed
// twice, in exact-size buffers from new (8-byte aligned, so a read past the end is an ASan report):
// as it is, and "repaired" (file size field and every checksum recomputed) so that mutations reach
// the checks behind the checksums. A refusal must say why. An accepted model is copied element by
// element through the view's pointers (ASan checks every one), must pass the writer's validation,
// and must parse back to a model that formats to the same bytes; then the runtime loads it (or
// refuses it, with the same message, where its energy falls along a mode: energyRisesAlongModes()),
// and evaluates and steps it once, flying too where it can (so its load-time expansion and first step meet hostile numbers
// too); anything else aborts.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "formats/model/qvr.h"
#include "formats/model/qvr_writer.h"
#include "quiver/quiver.h"
#include "tests/formats/model/qvr_test_files.h"

namespace {

// An exact-size copy from new (8-byte aligned), so that ASan reports any read past its end.
std::unique_ptr<unsigned char[]> exactCopy(const std::string& bytes) {
  std::unique_ptr<unsigned char[]> copy(new unsigned char[bytes.size()]);
  if (!bytes.empty()) std::memcpy(copy.get(), bytes.data(), bytes.size());
  return copy;
}

// The runtime on an accepted model: load, evaluate at a small q, create an instance, one step.
// `refusal`: the runtime's message for an energy that falls along a mode (energyRisesAlongModes()),
// or empty where it must load.
void runtimeSmoke(const void* data, size_t size, const std::string& refusal) {
  qv_model* model = nullptr;
  char message[1024];
  const qv_result loaded = qv_model_load_memory(data, size, nullptr, nullptr, &model, message, sizeof message);
  if (!refusal.empty()) {
    if (loaded != QV_ERROR_FORMAT || model || refusal != message) std::abort();
    return;
  }
  if (loaded != QV_OK) std::abort();
  qv_model_info info;
  qv_model_get_info(model, &info);
  std::vector<double> q(info.r, 1e-3), force(info.r), scratch(qv_model_scratch_size(model) / sizeof(double) + 1);
  qv_model_evaluate(model, q.data(), nullptr, force.data(), nullptr, scratch.data());
  qv_instance_config config;
  qv_instance_config_init(&config, model);
  qv_instance* instance = nullptr;
  if (qv_instance_create(model, &config, nullptr, &instance) == QV_OK) {
    qv_instance_set_state(instance, q.data(), nullptr, nullptr);
    qv_instance_step(instance);
    qv_instance_destroy(instance);
  }
  config.free_flight = info.has_rigid_body;  // a free model also flies: pushed off-centre, stepped, drawn
  if (config.free_flight && qv_instance_create(model, &config, nullptr, &instance) == QV_OK) {
    const double push[3] = {1, 2, 3};
    qv_instance_add_vertex_force(instance, 0, push);
    qv_instance_step(instance);
    std::vector<float> positions(3 * static_cast<size_t>(info.vertex_count));
    qv_instance_positions(instance, positions.data());
    qv_instance_destroy(instance);
  }
  qv_model_destroy(model);
}

void check(const std::string& input) {
  const std::unique_ptr<unsigned char[]> data = exactCopy(input);
  quiver::ModelView view;
  std::string error;
  if (!quiver::parseModel(data.get(), input.size(), view, error)) {
    if (error.empty()) std::abort();
    return;
  }
  const std::string bytes = quiver::formatModel(quiver::copyModel(view));  // throws (aborts) when refused
  const std::unique_ptr<unsigned char[]> formatted = exactCopy(bytes);
  quiver::ModelView again;
  if (!quiver::parseModel(formatted.get(), bytes.size(), again, error) ||
      quiver::formatModel(quiver::copyModel(again)) != bytes)
    std::abort();
  std::string falls;
  energyRisesAlongModes(data.get(), view, falls);
  runtimeSmoke(data.get(), input.size(), falls);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string input(reinterpret_cast<const char*>(data), size);
  check(input);
  if (size >= quiver::qvr::kHeaderSize) {
    quiver::test::putLE(input, quiver::qvr::kFileSizeAt, size, 8);
    quiver::test::reseal(input);
    check(input);
  }
  return 0;
}
