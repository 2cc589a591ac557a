#pragma once
// What the caller renders: displacements and positions of the simulated vertices (warped under
// modal warping) and surface normals, into caller-owned buffers.
#include "instance.h"

namespace quiver::rt {

void displacements(const qv_model& model, const double* q, float* out);           // U q, 3 per vertex
void simulatedDisplacements(const qv_instance& s, float* out);  // U q, warped under modal warping, 3 per vertex
// In flight, body-frame points (x + R (p - c)) and directions (R d) into the world, in place; else nothing.
void intoWorld(const qv_instance& s, float* points, size_t count);
void directionsIntoWorld(const qv_instance& s, float* directions, size_t count);
void positions(const qv_instance& s, float* out);                                  // all vertices
void positionsOf(const qv_instance& s, const int* vertices, int count, float* out);  // the listed ones
void surfaceNormals(const qv_model& model, const float* positions, float* normals);
// Unit normals of the triangles' vertices, area-weighted; 0 for vertices no triangle has.
void areaWeightedNormals(const float* positions, const unsigned* triangles, int triangleCount, int vertexCount, float* normals);

} // namespace quiver::rt
