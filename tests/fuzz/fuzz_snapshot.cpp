// libFuzzer target for restoring snapshots (qv_instance_restore_snapshot, qv_world_restore_snapshot:
// save games a game loads untrusted), under AddressSanitizer and UBSan. A small free bar
// (tests/support/small_model.h) drops onto the ground alone and onto another in a world, and each
// is saved in contact. Each input is then restored four ways: as it is, as an instance's and as a
// world's snapshot, and as edits to the saved ones (12 bytes an edit: a little-endian word index,
// taken modulo the snapshot's words, and the double to put there), so that mutations reach the
// checks behind the size and the state's. Each input starts from the saved snapshots. A refused
// snapshot must leave the instance or world as it was (saved again, the same bytes); an accepted
// one is stepped, and must step without a sanitizer report and leave a finite state or reset.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "quiver/quiver.h"
#include "tests/support/small_model.h"

namespace {

struct Scene {
  qv_model* model = nullptr;
  int r = 0;
  qv_instance* alone = nullptr;
  qv_instance* members[2] = {};
  qv_world* world = nullptr;
  qv_collider ground{};
  std::vector<double> aloneSaved, worldSaved;  // saved in contact, the bytes used
};

qv_instance* flyer(const qv_model* model, const qv_collider* ground, double height) {
  qv_instance_config config;
  qv_instance_config_init(&config, model);
  config.free_flight = 1;
  config.max_contacts = 16;
  qv_instance* s = nullptr;
  if (qv_instance_create(model, &config, nullptr, &s) != QV_OK) std::abort();
  const qv_rigid_state start = {{0.3, 0.05, height}, {0.96, 0.1, 0.2, 0.15}, {0.5, 0, 0}, {0, 1, 0}};
  const double gravity[3] = {0, 0, -QV_STANDARD_GRAVITY};
  qv_instance_set_rigid_state(s, &start);
  qv_instance_set_gravity(s, gravity);
  if (ground) qv_instance_set_colliders(s, ground, 1);
  return s;
}

std::vector<double> saved(size_t most, size_t used, const void* from) {
  std::vector<double> out(most / sizeof(double));
  std::memcpy(out.data(), from, used);
  out.resize(used / sizeof(double));
  return out;
}

Scene& scene() {
  static Scene s = [] {
    Scene made;
    quiver::test::SmallModelSpec spec;
    spec.cells = {6, 1, 1};
    spec.free = true;
    spec.rank = 8;
    const std::string bytes = quiver::formatModel(quiver::test::smallBeamModel(spec));
    if (qv_model_load_memory(bytes.data(), bytes.size(), nullptr, nullptr, &made.model, nullptr, 0) != QV_OK) std::abort();
    qv_model_info info;
    qv_model_get_info(made.model, &info);
    made.r = info.r;
    made.ground.type = QV_COLLIDER_PLANE;
    made.ground.data[2] = 1;
    made.ground.friction = 0.5;
    made.alone = flyer(made.model, &made.ground, 0.15);
    qv_world_config config;
    qv_world_config_init(&config);
    config.max_instances = 2;
    config.max_contacts = 64;
    if (qv_world_create(&config, nullptr, &made.world) != QV_OK) std::abort();
    made.members[0] = flyer(made.model, nullptr, 0.15);
    made.members[1] = flyer(made.model, nullptr, 0.3);
    for (qv_instance* m : made.members) qv_world_add(made.world, m, nullptr);
    qv_world_set_colliders(made.world, &made.ground, 1);
    for (int i = 0; i < 40; ++i) qv_instance_step(made.alone), qv_world_step(made.world);
    if (!qv_instance_contacts(made.alone, nullptr, 0) || !qv_world_contacts(made.world, nullptr, 0)) std::abort();
    std::vector<double> block(qv_world_snapshot_size(made.world) / sizeof(double));
    made.worldSaved = saved(block.size() * sizeof(double), qv_world_save_snapshot(made.world, block.data()), block.data());
    block.assign(qv_instance_snapshot_size(made.alone) / sizeof(double), 0);
    made.aloneSaved = saved(block.size() * sizeof(double), qv_instance_save_snapshot(made.alone, block.data()), block.data());
    return made;
  }();
  return s;
}

// What a save gives now: refusals must not change it.
std::vector<double> now(const Scene& s, bool world) {
  std::vector<double> block((world ? qv_world_snapshot_size(s.world) : qv_instance_snapshot_size(s.alone)) / sizeof(double));
  const size_t used = world ? qv_world_save_snapshot(s.world, block.data()) : qv_instance_save_snapshot(s.alone, block.data());
  block.resize(used / sizeof(double));
  return block;
}

bool finite(const qv_instance* s, int r) {
  std::vector<double> q(r), v(r);
  qv_instance_get_state(s, q.data(), v.data(), nullptr);
  qv_rigid_state state;
  qv_instance_get_rigid_state(s, &state);
  for (int i = 0; i < r; ++i)
    if (!std::isfinite(q[i]) || !std::isfinite(v[i])) return false;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(state.position[a]) || !std::isfinite(state.linear_velocity[a])) return false;
  return true;
}

// Restores `bytes` (8-byte aligned) into the instance or the world; refused: unchanged; accepted:
// stepped twice, finite.
void restore(Scene& s, bool world, const std::vector<double>& bytesAligned, size_t size) {
  const std::vector<double> before = now(s, world);
  const qv_result result = world ? qv_world_restore_snapshot(s.world, bytesAligned.data(), size)
                                 : qv_instance_restore_snapshot(s.alone, bytesAligned.data(), size);
  if (result != QV_OK) {
    // Bit for bit: a step that reset may leave a NaN among the last step's forces.
    const std::vector<double> after = now(s, world);
    if (result != QV_ERROR_INVALID_ARGUMENT || after.size() != before.size() ||
        std::memcmp(after.data(), before.data(), after.size() * sizeof(double)) != 0)
      std::abort();
    return;
  }
  for (int i = 0; i < 2; ++i) {
    if (world) {
      qv_world_step(s.world);
      if (!finite(s.members[0], s.r) || !finite(s.members[1], s.r)) std::abort();
    } else {
      qv_instance_step(s.alone);
      if (!finite(s.alone, s.r)) std::abort();
    }
  }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Scene& s = scene();
  // Each input from the same start, so that a crash repeats from its input alone.
  if (qv_instance_restore_snapshot(s.alone, s.aloneSaved.data(), s.aloneSaved.size() * sizeof(double)) != QV_OK ||
      qv_world_restore_snapshot(s.world, s.worldSaved.data(), s.worldSaved.size() * sizeof(double)) != QV_OK)
    std::abort();
  std::vector<double> raw(size / sizeof(double) + 1);
  if (size) std::memcpy(raw.data(), data, size);
  restore(s, false, raw, size);
  restore(s, true, raw, size);
  for (const bool world : {false, true}) {
    std::vector<double> edited = world ? s.worldSaved : s.aloneSaved;
    for (size_t at = 0; at + 12 <= size; at += 12) {
      uint32_t word;
      std::memcpy(&word, data + at, 4);
      std::memcpy(&edited[word % edited.size()], data + at + 4, 8);
    }
    restore(s, world, edited, edited.size() * sizeof(double));
  }
  return 0;
}
