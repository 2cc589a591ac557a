#include "broad_phase.h"

#include <algorithm>

namespace quiver::rt {

void BroadPhase::carve(BlockCarver& c, int bodies) {
  const size_t n = static_cast<size_t>(bodies);
  capacity = bodies;
  centres = c.take<double>(3 * n);
  halfWidth = c.take<double>(n);
  low = c.take<double>(n);
  high = c.take<double>(n);
  order = c.take<int>(n);
  rowStart = c.take<int>(n + 1);
  neighbourCapacity = kNeighboursPerBody * bodies;
  neighbours = c.take<int>(static_cast<size_t>(neighbourCapacity));
}

void sortIntervals(BroadPhase& b, int count) {
  // The axis of the centres' largest variance: along it the fewest intervals overlap.
  double mean[3] = {}, spread[3] = {};
  for (int i = 0; i < count; ++i)
    for (int a = 0; a < 3; ++a) mean[a] += b.centres[3 * i + a] / count;
  for (int i = 0; i < count; ++i)
    for (int a = 0; a < 3; ++a) spread[a] += (b.centres[3 * i + a] - mean[a]) * (b.centres[3 * i + a] - mean[a]);
  const int axis = static_cast<int>(std::max_element(spread, spread + 3) - spread);
  for (int i = 0; i < count; ++i) {
    b.low[i] = b.centres[3 * i + axis] - b.halfWidth[i];
    b.high[i] = b.centres[3 * i + axis] + b.halfWidth[i];
    b.order[i] = i;
  }
  std::sort(b.order, b.order + count, [&](int i, int j) { return b.low[i] < b.low[j] || (b.low[i] == b.low[j] && i < j); });
  b.count = count;
}

void listOverlaps(BroadPhase& b) {
  // Counted, then placed (each pair in both rows), then each row sorted.
  std::fill(b.rowStart, b.rowStart + b.count + 1, 0);
  long long total = 0;
  forEachOverlap(b, [&](int i, int j) { ++b.rowStart[i + 1], ++b.rowStart[j + 1], total += 2; });
  b.rowsValid = total <= b.neighbourCapacity;
  if (!b.rowsValid) return;
  for (int i = 0; i < b.count; ++i) b.rowStart[i + 1] += b.rowStart[i];
  // rowStart[i] is used as row i's fill point, then restored from the next row's start.
  forEachOverlap(b, [&](int i, int j) { b.neighbours[b.rowStart[i]++] = j, b.neighbours[b.rowStart[j]++] = i; });
  for (int i = b.count; i > 0; --i) b.rowStart[i] = b.rowStart[i - 1];
  b.rowStart[0] = 0;
  for (int i = 0; i < b.count; ++i) std::sort(b.neighbours + b.rowStart[i], b.neighbours + b.rowStart[i + 1]);
}

} // namespace quiver::rt
