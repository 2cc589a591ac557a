/* rollback: rewinding a scene for rollback netcode, in plain C. A few free bars drop onto the ground
   and onto each other in one world. A peer's input (a push on one bar) meant for an earlier frame
   arrives late: the game restores the world's snapshot of that frame, applies the input there and
   steps the frames again. The result must be what a game that had the input in time computed, bit
   for bit, contacts and sleeping included; the program checks that against a second world that
   got the input on time.

     rollback FREE_MODEL.qvr */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "quiver/quiver.h"

enum { kBars = 4, kFrames = 150, kHistory = 8, kInputFrame = 84, kArrivesAt = 90 };

typedef struct Scene {
  qv_world* world;
  qv_instance* bars[kBars];
} Scene;

static int makeScene(const qv_model* model, const qv_collider* ground, Scene* scene) {
  if (qv_world_create(NULL, NULL, &scene->world) != QV_OK) return 0;
  qv_instance_config config;
  qv_instance_config_init(&config, model);
  config.free_flight = 1;
  config.time_step = 1.0 / 60.0;
  const double gravity[3] = {0, 0, -QV_STANDARD_GRAVITY};
  for (int i = 0; i < kBars; ++i) {
    if (qv_instance_create(model, &config, NULL, &scene->bars[i]) != QV_OK) return 0;
    qv_rigid_state start = {{0.3, 0.05, 0.1 + 0.15 * i}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    if (i % 2) start.orientation[0] = start.orientation[3] = 0.70710678118654752; /* crosswise */
    qv_instance_set_rigid_state(scene->bars[i], &start);
    qv_instance_set_gravity(scene->bars[i], gravity);
    qv_world_add(scene->world, scene->bars[i], NULL);
  }
  return qv_world_set_colliders(scene->world, ground, 1) == QV_OK;
}

static void destroyScene(Scene* scene) {
  qv_world_destroy(scene->world);
  for (int i = 0; i < kBars; ++i) qv_instance_destroy(scene->bars[i]);
}

/* The peer's input: a sideways shove on the top bar's vertex 0. */
static void applyInput(Scene* scene, const qv_model_info* info) {
  const double push[3] = {0, 40 * info->total_mass * QV_STANDARD_GRAVITY, 0};
  qv_instance_add_vertex_force(scene->bars[kBars - 1], 0, push);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: rollback FREE_MODEL.qvr\n");
    return 2;
  }
  char message[512];
  qv_model* model = NULL;
  if (qv_model_load_file(argv[1], NULL, NULL, &model, message, sizeof message) != QV_OK) {
    fprintf(stderr, "rollback: %s\n", message);
    return 1;
  }
  qv_model_info info;
  qv_model_get_info(model, &info);
  qv_collider ground;
  memset(&ground, 0, sizeof ground);
  ground.type = QV_COLLIDER_PLANE;
  ground.data[2] = 1; /* n = +z through the origin */
  ground.friction = 0.5;
  Scene late, onTime;
  if (!makeScene(model, &ground, &late) || !makeScene(model, &ground, &onTime)) {
    fprintf(stderr, "rollback: %s is not a free model (bake it without --fix)\n", argv[1]);
    return 1;
  }

  /* A ring of the last kHistory frames' snapshots, each taken before its frame's step: the most a
     snapshot takes, of which each keeps what its save used. */
  const size_t most = qv_world_snapshot_size(late.world);
  double* history = malloc(most * kHistory); /* doubles: snapshots want 8-byte alignment */
  size_t used[kHistory];
  if (!history) return 1;
  int replayed = 0;
  for (int frame = 0; frame < kFrames; ++frame) {
    if (frame == kArrivesAt) { /* the input for kInputFrame arrives: rewind and step again */
      const int slot = kInputFrame % kHistory;
      if (qv_world_restore_snapshot(late.world, (char*)history + most * slot, used[slot]) != QV_OK) return 1;
      for (int again = kInputFrame; again < frame; ++again, ++replayed) {
        used[again % kHistory] = qv_world_save_snapshot(late.world, (char*)history + most * (again % kHistory));
        if (again == kInputFrame) applyInput(&late, &info);
        qv_world_step(late.world);
      }
    }
    used[frame % kHistory] = qv_world_save_snapshot(late.world, (char*)history + most * (frame % kHistory));
    qv_world_step(late.world);
    if (frame == kInputFrame) applyInput(&onTime, &info);
    qv_world_step(onTime.world);
  }

  /* Both worlds, vertex by vertex, and whether they sleep. */
  float* a = malloc(sizeof(float) * 3 * (size_t)info.vertex_count);
  float* b = malloc(sizeof(float) * 3 * (size_t)info.vertex_count);
  if (!a || !b) return 1;
  int same = 1, asleep = 0;
  for (int i = 0; i < kBars; ++i) {
    qv_instance_positions(late.bars[i], a);
    qv_instance_positions(onTime.bars[i], b);
    same &= memcmp(a, b, sizeof(float) * 3 * (size_t)info.vertex_count) == 0;
    same &= qv_instance_asleep(late.bars[i]) == qv_instance_asleep(onTime.bars[i]);
    asleep += qv_instance_asleep(late.bars[i]);
  }
  qv_rigid_state top;
  qv_instance_get_rigid_state(late.bars[kBars - 1], &top);
  printf("rollback: input for frame %d arrived at frame %d, %d frames stepped again (snapshots of %zu bytes at most, "
         "%zu used at the last frame); after %d frames the top bar is at (%.3f, %.3f, %.3f), %d of %d asleep; the "
         "same as the world that had the input in time, bit for bit: %s\n",
         kInputFrame, kArrivesAt, replayed, most, used[(kFrames - 1) % kHistory], kFrames, top.position[0],
         top.position[1], top.position[2], asleep, kBars, same ? "yes" : "NO");
  free(a);
  free(b);
  free(history);
  destroyScene(&late);
  destroyScene(&onTime);
  qv_model_destroy(model);
  return same ? 0 : 1;
}
