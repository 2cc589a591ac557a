/* debris: pieces a game spawns and despawns in a world, stepped on the game's own threads, in plain
   C. A piece drops onto the ground every 8 frames; once 8 are out, the oldest is despawned
   (qv_world_remove) and reused for the next. The world's steps run on two threads through the
   game's job runner (qv_world_set_jobs; the runtime starts no threads): the program checks the
   pieces bit for bit against a second world stepped on the calling thread.

     debris FREE_MODEL.qvr */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "quiver/quiver.h"

enum { kPieces = 12, kOut = 8, kEvery = 8, kFrames = 480 };

typedef struct Pieces {
  qv_world* world;
  qv_instance* pieces[kPieces];
  int out[kOut]; /* the pieces in the world, oldest first */
  int outCount, next;
} Pieces;

/* The game's job runner: job 0 on the calling thread, the others on threads of their own. A game
   would keep a pool; a thread per job keeps the example short. */
typedef struct JobArgs {
  qv_job_function job;
  void* data;
  int index;
} JobArgs;

static void* runOne(void* p) {
  const JobArgs* a = p;
  a->job(a->data, a->index);
  return NULL;
}

static void runOnThreads(void* user, qv_job_function job, void* data, int count) {
  enum { kMost = 8 };
  pthread_t threads[kMost];
  JobArgs args[kMost];
  int made[kMost] = {0};
  (void)user;
  for (int i = 1; i < count; ++i) {
    if (i < kMost) {
      args[i] = (JobArgs){job, data, i};
      made[i] = pthread_create(&threads[i], NULL, runOne, &args[i]) == 0;
    }
    if (i >= kMost || !made[i]) job(data, i); /* no thread for it: here */
  }
  job(data, 0);
  for (int i = 1; i < count && i < kMost; ++i)
    if (made[i]) pthread_join(threads[i], NULL);
}

static int makePieces(const qv_model* model, const qv_collider* ground, Pieces* p) {
  memset(p, 0, sizeof *p);
  if (qv_world_create(NULL, NULL, &p->world) != QV_OK) return 0;
  qv_instance_config config;
  qv_instance_config_init(&config, model);
  config.free_flight = 1;
  config.time_step = 1.0 / 60.0;
  const double gravity[3] = {0, 0, -QV_STANDARD_GRAVITY};
  for (int i = 0; i < kPieces; ++i) {
    if (qv_instance_create(model, &config, NULL, &p->pieces[i]) != QV_OK) return 0;
    qv_instance_set_gravity(p->pieces[i], gravity);
  }
  return qv_world_set_colliders(p->world, ground, 1) == QV_OK;
}

/* Frame `frame`'s spawn: the oldest piece out comes back (despawned first) when all kOut are out. */
static int spawn(Pieces* p, int frame) {
  int piece;
  if (p->outCount == kOut) {
    piece = p->out[0];
    if (qv_world_remove(p->world, p->pieces[piece]) != QV_OK) return 0;
    memmove(p->out, p->out + 1, sizeof(int) * (kOut - 1));
    --p->outCount;
  } else {
    piece = p->next++;
  }
  /* Somewhere over a patch of 1.2 m, tumbling a little, from the frame number alone. */
  const double x = 0.15 * (frame % 7) - 0.45, y = 0.2 * (frame % 5) - 0.4, turn = 0.3 * (frame % 11);
  const qv_rigid_state start = {{x, y, 0.5}, {1, 0, 0, 0}, {0, 0, -1}, {turn, 0.5 * turn, 0}};
  qv_instance_reset(p->pieces[piece]); /* a reused piece: undeformed, at rest */
  if (qv_instance_set_rigid_state(p->pieces[piece], &start) != QV_OK) return 0;
  if (qv_world_add(p->world, p->pieces[piece], NULL) != QV_OK) return 0;
  p->out[p->outCount++] = piece;
  return 1;
}

static void destroyPieces(Pieces* p) {
  qv_world_destroy(p->world);
  for (int i = 0; i < kPieces; ++i) qv_instance_destroy(p->pieces[i]);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: debris FREE_MODEL.qvr\n");
    return 2;
  }
  char message[512];
  qv_model* model = NULL;
  if (qv_model_load_file(argv[1], NULL, NULL, &model, message, sizeof message) != QV_OK) {
    fprintf(stderr, "debris: %s\n", message);
    return 1;
  }
  qv_model_info info;
  qv_model_get_info(model, &info);
  qv_collider ground;
  memset(&ground, 0, sizeof ground);
  ground.type = QV_COLLIDER_PLANE;
  ground.data[2] = 1; /* n = +z through the origin */
  ground.friction = 0.5;
  Pieces threaded, alone;
  if (!makePieces(model, &ground, &threaded) || !makePieces(model, &ground, &alone)) {
    fprintf(stderr, "debris: %s is not a free model (bake it without --fix)\n", argv[1]);
    return 1;
  }
  const qv_job_runner jobs = {2, runOnThreads, NULL};
  if (qv_world_set_jobs(threaded.world, &jobs) != QV_OK) return 1;

  int resets = 0, despawned = 0;
  for (int frame = 0; frame < kFrames; ++frame) {
    if (frame % kEvery == 0) {
      despawned += threaded.outCount == kOut;
      if (!spawn(&threaded, frame) || !spawn(&alone, frame)) return 1;
    }
    resets += qv_world_step(threaded.world);
    resets += qv_world_step(alone.world);
  }

  /* The pieces out, vertex by vertex, and whether they sleep. */
  float* a = malloc(sizeof(float) * 3 * (size_t)info.vertex_count);
  float* b = malloc(sizeof(float) * 3 * (size_t)info.vertex_count);
  if (!a || !b) return 1;
  int same = 1, asleep = 0;
  for (int k = 0; k < threaded.outCount; ++k) {
    qv_instance_positions(threaded.pieces[threaded.out[k]], a);
    qv_instance_positions(alone.pieces[alone.out[k]], b);
    same &= memcmp(a, b, sizeof(float) * 3 * (size_t)info.vertex_count) == 0;
    same &= qv_instance_asleep(threaded.pieces[threaded.out[k]]) == qv_instance_asleep(alone.pieces[alone.out[k]]);
    asleep += qv_instance_asleep(threaded.pieces[threaded.out[k]]);
  }
  printf("debris: %d frames, a piece every %d, %d despawned to make room; %d out at the end, %d of them asleep, %d resets; "
         "on two threads the same as on one, bit for bit: %s\n",
         kFrames, kEvery, despawned, threaded.outCount, asleep, resets, same ? "yes" : "NO");
  free(a);
  free(b);
  destroyPieces(&threaded);
  destroyPieces(&alone);
  qv_model_destroy(model);
  return same && resets == 0 ? 0 : 1;
}
