#include "contact_modes.h"

#include <cmath>
#include <cstring>

#include "block_carver.h"
#include "dense_solve.h"
#include "model.h"

namespace quiver::rt {

namespace {

struct Parts {
  double *stiffness, *vectors, *rows;
  int* pointOf;
};

// Lays the modes out in `block` (null: only measures); returns its size.
size_t layOut(const qv_model& m, char* block, Parts& p) {
  const size_t r = static_cast<size_t>(m.info.r), n = static_cast<size_t>(m.info.vertex_count);
  BlockCarver c(block);
  p.stiffness = c.take<double>(r);
  p.vectors = c.take<double>(r * r);
  p.rows = c.take<double>(static_cast<size_t>(m.contactCount) * 3 * r);
  p.pointOf = c.take<int>(n);
  return c.size();
}

} // namespace

bool buildContactModes(const qv_model& m, const qv_allocator& allocator, ContactModes& out) {
  const int r = m.info.r;
  Parts p;
  const size_t bytes = layOut(m, nullptr, p);
  char* block = static_cast<char*>(allocator.allocate(bytes, 64, allocator.user));
  // K(0), diagonalised in place: scratch for the load only.
  double* A = static_cast<double*>(allocator.allocate(sizeof(double) * r * r, 64, allocator.user));
  if (!block || !A) {
    if (block) allocator.release(block, allocator.user);
    if (A) allocator.release(A, allocator.user);
    return false;
  }
  layOut(m, block, p);
  std::memcpy(A, m.restStiffness, sizeof(double) * r * r);
  symmetricEigen(A, p.vectors, r);
  for (int i = 0; i < r; ++i) p.stiffness[i] = std::fmax(A[i * r + i], 0.0);  // K(0) is PSD but for rounding
  allocator.release(A, allocator.user);
  for (int v = 0; v < m.info.vertex_count; ++v) p.pointOf[v] = -1;
  const double* V = p.vectors;
  for (int k = 0; k < m.contactCount; ++k) {
    const int v = m.contactVertices[k];
    p.pointOf[v] = k;
    for (int a = 0; a < 3; ++a) {
      double* row = p.rows + (static_cast<size_t>(k) * 3 + a) * r;
      for (int i = 0; i < r; ++i) {
        double sum = 0;
        for (int j = 0; j < r; ++j) sum += m.basisEntry(3 * static_cast<size_t>(v) + a, j) * V[j * r + i];
        row[i] = sum;
      }
    }
  }
  out = ContactModes{p.stiffness, p.vectors, p.rows, p.pointOf, block};
  return true;
}

void destroyContactModes(ContactModes& modes, const qv_allocator& allocator) {
  if (modes.block) allocator.release(modes.block, allocator.user);
  modes = ContactModes{};
}

} // namespace quiver::rt
