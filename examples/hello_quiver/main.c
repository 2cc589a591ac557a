/* hello_quiver: the smallest use of the Quiver runtime, in plain C.
   Loads a baked model, checks the library version, reports what it holds, and evaluates the
   reduced elastic force for a deformation along the first basis vector.

     hello_quiver MODEL.qvr */
#include <stdio.h>
#include <stdlib.h>

#include "quiver/quiver.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: hello_quiver MODEL.qvr\n");
    return 2;
  }
  if (!QV_CHECK_VERSION()) {
    fprintf(stderr, "hello_quiver: built against another version of the Quiver runtime (%s)\n", qv_version_string());
    return 1;
  }

  qv_model* model = NULL;
  char message[512];
  qv_result result = qv_model_load_file(argv[1], NULL, NULL, &model, message, sizeof message);
  if (result != QV_OK) {
    fprintf(stderr, "hello_quiver: %s: %s\n", qv_result_string(result), message);
    return 1;
  }

  qv_model_info info;
  qv_model_get_info(model, &info);
  printf("model: r = %d, %d vertices, %d tets, %d surface triangles, %.4g kg\n", info.r, info.vertex_count,
         info.tet_count, info.triangle_count, info.total_mass);

  /* Caller-owned memory: the library allocates nothing while evaluating. */
  double* q = calloc((size_t)info.r, sizeof(double));
  double* force = calloc((size_t)info.r, sizeof(double));
  void* scratch = malloc(qv_model_scratch_size(model));
  float* displacement = malloc(3 * (size_t)info.vertex_count * sizeof(float));
  if (!q || !force || !scratch || !displacement) {
    fprintf(stderr, "hello_quiver: out of memory\n");
    return 1;
  }

  /* Pull along the first basis vector until some vertex moves 1% of the model's size. */
  q[0] = 1.0;
  qv_model_displacements(model, q, displacement);
  double largest = 0, size = info.bbox_max[0] - info.bbox_min[0];
  for (int i = 0; i < 3 * info.vertex_count; ++i)
    if (displacement[i] > largest || -displacement[i] > largest) largest = displacement[i] > 0 ? displacement[i] : -displacement[i];
  q[0] = 0.01 * size / largest;

  double energy = 0;
  qv_model_evaluate(model, q, &energy, force, NULL, scratch);
  printf("q[0] = %.6g: elastic energy %.6g J, restoring force on q[0] %.6g\n", q[0], energy, force[0]);

  free(displacement);
  free(scratch);
  free(force);
  free(q);
  qv_model_destroy(model);
  return 0;
}
