#pragma once
// How a free model's deformation gives way where a contact pushes: its rest stiffness's modes,
// K(0) = V diag(lambda) V^T, and the rows of U V at each contact point (contact_points.h). In those
// modes an implicit step's response to a force is diagonal (qv_instance::modeCompliance), so a
// contact solve can follow how its impulses move the surface in O(r) per contact, with no r x r
// solve and nothing stored per contact (contact.cpp). Built at load for every free model: 24 r
// bytes per surface vertex, and a Jacobi diagonalisation of K(0).
#include "quiver/quiver.h"

struct qv_model;

namespace quiver::rt {

struct ContactModes {
  const double* stiffness = nullptr;  // lambda (r), clamped at 0
  const double* vectors = nullptr;    // V, r x r row-major, the modes as its columns
  const double* rows = nullptr;       // per contact point: 3 rows of r, (U V) at its vertex
  const int* pointOf = nullptr;       // vertex -> contact point, -1 off the surface
  void* block = nullptr;              // the one allocation holding them

  // Contact point k's rows, or null for a vertex that is not one.
  const double* rowsOf(int vertex, int r) const {
    const int k = pointOf ? pointOf[vertex] : -1;
    return k >= 0 ? rows + static_cast<size_t>(k) * 3 * r : nullptr;
  }
};

// Builds m's contact modes (m.contactVertices, m.restStiffness) in one block from `allocator`;
// false when it fails.
bool buildContactModes(const qv_model& m, const qv_allocator& allocator, ContactModes& out);
void destroyContactModes(ContactModes& modes, const qv_allocator& allocator);

} // namespace quiver::rt
