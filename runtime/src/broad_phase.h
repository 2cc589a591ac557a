#pragma once
// The broad phase of a world's contact solve (contact.h): which pairs of bodies may come within
// reach of each other in a step, so that the exact tests (bounding spheres within reach) run on
// those alone rather than on all N^2 pairs. Each body is an interval along one axis, its centre
// plus and minus a half width that bounds its reach (bounding sphere, slop, and what it and its
// group cover in the step; not NaN). Two bodies whose intervals do not overlap cannot be within
// reach: their centres' distance is at least its part along any axis. A sort along the axis on
// which the centres spread most, then a sweep. The caller's memory; no allocation.
#include "block_carver.h"

namespace quiver::rt {

struct BroadPhase {
  int capacity = 0;               // bodies
  double* centres = nullptr;      // 3 per body, filled by the caller
  double* halfWidth = nullptr;    // per body, filled by the caller
  double* low = nullptr;          // per body: its interval along the axis (sortIntervals())
  double* high = nullptr;
  int* order = nullptr;           // the bodies by their interval's low end
  int count = 0;                  // bodies sorted
  // Each body's overlaps in ascending order (listOverlaps()): body i's are
  // neighbours[rowStart[i], rowStart[i + 1]), when all fit (rowsValid).
  int* rowStart = nullptr;        // capacity + 1
  int* neighbours = nullptr;      // neighbourCapacity
  int neighbourCapacity = 0;
  bool rowsValid = false;

  static constexpr int kNeighboursPerBody = 64;  // room for this many overlaps per body on average
  void carve(BlockCarver& c, int bodies);
};

// Sorts the first `count` bodies' intervals (centres and halfWidth filled) along the axis on which
// their centres spread most.
void sortIntervals(BroadPhase& b, int count);

// Calls visit(i, j) once for each pair of bodies whose intervals overlap (sortIntervals() first).
template <class Visit>
void forEachOverlap(const BroadPhase& b, Visit visit) {
  for (int a = 0; a < b.count; ++a) {
    const int i = b.order[a];
    for (int k = a + 1; k < b.count && b.low[b.order[k]] <= b.high[i]; ++k) visit(i, b.order[k]);
  }
}

// Lists each body's overlaps in ascending order; rowsValid says whether they all fit.
void listOverlaps(BroadPhase& b);

} // namespace quiver::rt
