#pragma once
// A free model's contact points: its surface vertices, each with a level, listed from the highest
// level down. Level L + 1 keeps, of the level-L vertices in each cell of a grid twice as coarse, the
// one nearest the cell's centre: every level and above is spread evenly over the surface, about
// twice as sparse as the one below. When more vertices touch than an instance keeps contacts,
// contact.cpp keeps each touching patch down to a level (a spread subset), not its deepest vertices:
// those sat on one side of a resting face, then on the other as it tilted, and it rocked forever.
#include "quiver/quiver.h"

namespace quiver::rt {

inline constexpr int kContactLevels = 16;  // levels above the last count as the last

// Fills `vertices` (vertex_count slots) and `levels` with the surface vertices of `triangles` and
// their levels; returns how many, or -1 when `allocator` fails for the few bytes per vertex it needs.
int orderContactPoints(const double* rest, int vertexCount, const unsigned* triangles, int triangleCount,
                       const qv_allocator& allocator, int* vertices, unsigned char* levels);

} // namespace quiver::rt
