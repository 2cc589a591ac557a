/* embed: the Quiver runtime in a game loop, in plain C. Load a model once, create an object,
   then every frame: apply the player's input as a force, step at a fixed 60 Hz, and hand the
   vertex positions to the renderer. No allocation happens inside the loop.

     embed MODEL.qvr [frames] */
#include <stdio.h>
#include <stdlib.h>

#include "quiver/quiver.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: embed MODEL.qvr [frames]\n");
    return 2;
  }
  const int frames = argc > 2 ? atoi(argv[2]) : 300;
  char message[512];
  qv_model* model = NULL;
  if (qv_model_load_file(argv[1], NULL, NULL, &model, message, sizeof message) != QV_OK) {
    fprintf(stderr, "embed: %s\n", message);
    return 1;
  }
  qv_model_info info;
  qv_model_get_info(model, &info);

  qv_instance_config config;
  qv_instance_config_init(&config, model);
  config.time_step = 1.0 / 60.0; /* the game's fixed physics rate */
  qv_instance* object = NULL;
  if (qv_instance_create(model, &config, NULL, &object) != QV_OK) return 1;
  const double gravity[3] = {0, 0, -QV_STANDARD_GRAVITY};
  qv_instance_set_gravity(object, gravity);

  /* The renderer's vertex buffer, owned by the game. */
  float* positions = malloc(sizeof(float) * 3 * (size_t)info.vertex_count);
  if (!positions) return 1;
  /* "The player" pushes the vertex farthest along +x sideways for the first second. */
  const double* rest = qv_model_rest_positions(model);
  int handle = 0;
  for (int v = 1; v < info.vertex_count; ++v)
    if (rest[3 * v] > rest[3 * handle]) handle = v;
  const double push[3] = {0, 0.02 * info.total_mass * QV_STANDARD_GRAVITY, 0};

  for (int frame = 0; frame < frames; ++frame) {
    if (frame < 60) qv_instance_add_vertex_force(object, handle, push);
    if (qv_instance_step(object) == QV_STEP_RESET) fprintf(stderr, "embed: frame %d: the object was reset\n", frame);
    qv_instance_positions(object, positions); /* upload to the GPU here */
  }
  printf("after %d frames (%.2f s): handle vertex at (%.4f, %.4f, %.4f), rest (%.4f, %.4f, %.4f)\n", frames,
         frames * config.time_step, positions[3 * handle], positions[3 * handle + 1], positions[3 * handle + 2],
         rest[3 * handle], rest[3 * handle + 1], rest[3 * handle + 2]);

  free(positions);
  qv_instance_destroy(object);
  qv_model_destroy(model);
  return 0;
}
