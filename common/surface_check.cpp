#include "common/surface_check.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/mesh_error.h"

namespace quiver {

namespace {

using Vec = Eigen::Vector3d;
using Edge = std::pair<int, int>;

Vec at(const std::vector<double>& x, int v) { return {x[3 * v], x[3 * v + 1], x[3 * v + 2]}; }

std::string where(const std::vector<double>& x, int v) {
  const Vec p = at(x, v);
  char text[128];
  std::snprintf(text, sizeof text, "vertex %d (%.6g, %.6g, %.6g)", v, p[0], p[1], p[2]);
  return text;
}

// Segment pq against triangle abc: true when it crosses the triangle's interior (Moller-Trumbore,
// endpoints and edges excluded by a small margin so that touching is not crossing).
bool segmentCrosses(const Vec& p, const Vec& q, const Vec& a, const Vec& b, const Vec& c) {
  const Vec d = q - p, e1 = b - a, e2 = c - a, h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::fabs(det) < 1e-14 * d.norm() * e1.norm() * e2.norm()) return false;  // parallel or coplanar
  const double f = 1 / det;
  const Vec s = p - a;
  const double u = f * s.dot(h);
  const Vec k = s.cross(e1);
  const double v = f * d.dot(k), t = f * e2.dot(k);
  constexpr double eps = 1e-9;
  return u > eps && v > eps && u + v < 1 - eps && t > eps && t < 1 - eps;
}

bool trianglesCross(const std::vector<double>& x, const std::array<int, 3>& A, const std::array<int, 3>& B) {
  for (int k = 0; k < 3; ++k) {
    if (segmentCrosses(at(x, A[k]), at(x, A[(k + 1) % 3]), at(x, B[0]), at(x, B[1]), at(x, B[2]))) return true;
    if (segmentCrosses(at(x, B[k]), at(x, B[(k + 1) % 3]), at(x, A[0]), at(x, A[1]), at(x, A[2]))) return true;
  }
  return false;
}

// Pairs of triangles sharing no vertex that cross, found through a uniform grid of their boxes.
std::vector<std::pair<int, int>> crossings(const std::vector<double>& x, const std::vector<std::array<int, 3>>& tris, size_t limit) {
  Eigen::AlignedBox3d all;
  double edges = 0;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) all.extend(at(x, t[k])), edges += (at(x, t[k]) - at(x, t[(k + 1) % 3])).norm();
  const double cell = std::max(2 * edges / (3.0 * tris.size()), all.diagonal().maxCoeff() / 1024);
  std::unordered_map<long long, std::vector<int>> grid;
  const auto key = [&](const Vec& p, int a) { return static_cast<long long>(std::floor((p[a] - all.min()[a]) / cell)); };
  for (size_t i = 0; i < tris.size(); ++i) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 3; ++k) box.extend(at(x, tris[i][k]));
    for (long long gx = key(box.min(), 0); gx <= key(box.max(), 0); ++gx)
      for (long long gy = key(box.min(), 1); gy <= key(box.max(), 1); ++gy)
        for (long long gz = key(box.min(), 2); gz <= key(box.max(), 2); ++gz)
          grid[(gx * 2048 + gy) * 2048 + gz].push_back(static_cast<int>(i));
  }
  std::vector<std::pair<int, int>> found;
  for (const auto& [cellKey, members] : grid)
    for (size_t a = 0; a < members.size(); ++a)
      for (size_t b = a + 1; b < members.size(); ++b) {
        const auto &A = tris[members[a]], &B = tris[members[b]];
        bool shared = false;
        for (int i : A) shared = shared || std::count(B.begin(), B.end(), i);
        if (shared || !trianglesCross(x, A, B)) continue;
        const std::pair<int, int> pair = std::minmax(members[a], members[b]);
        if (std::find(found.begin(), found.end(), pair) == found.end()) found.push_back(pair);
        if (found.size() >= limit) return found;
      }
  std::sort(found.begin(), found.end());
  return found;
}

// Winding number of closed triangles around p (Van Oosterom-Strackee solid angles): ~1 inside.
double winding(const std::vector<double>& x, const std::vector<std::array<int, 3>>& tris, const Vec& p) {
  double sum = 0;
  for (const auto& t : tris) {
    const Vec a = at(x, t[0]) - p, b = at(x, t[1]) - p, c = at(x, t[2]) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return sum / (4 * M_PI);
}

} // namespace

double enclosedVolume(const std::vector<double>& x, const std::vector<std::array<int, 3>>& tris) {
  double six = 0;
  for (const auto& t : tris) six += at(x, t[0]).dot(at(x, t[1]).cross(at(x, t[2])));
  return six / 6;
}

CheckedSurface checkSurface(const std::vector<double>& inputPositions, const std::vector<int>& input, const std::string& name,
                            const SurfaceCheckOptions& options) {
  const auto fail = [&](const std::string& what) { throw MeshError(name + ": " + what); };
  CheckedSurface out;
  out.positions = inputPositions;
  const std::vector<double>& positions = out.positions;  // holes add their centres
  const int n = static_cast<int>(positions.size() / 3);
  for (int v = 0; v < n; ++v)
    for (int a = 0; a < 3; ++a) {
      const double c = positions[3 * v + a];
      if (!std::isfinite(c)) fail(where(positions, v) + ": a coordinate is not finite");
      if (std::fabs(c) > 1e9) fail(where(positions, v) + ": a coordinate beyond 1e9 (in metres?): scale the surface first");
    }
  // The bake works in metres: a surface a micrometre across or less (a file in kilometres? a scale
  // gone wrong?) failed late and obscurely, in the eigensolver or the export.
  Vec low = Vec::Constant(INFINITY), high = -low;
  for (int v = 0; v < n; ++v) low = low.cwiseMin(at(positions, v)), high = high.cwiseMax(at(positions, v));
  if (n > 0 && !((high - low).maxCoeff() > 1e-6)) {
    std::ostringstream span;
    span << (high - low).maxCoeff();
    fail("the surface spans " + span.str() + " m at most, under a micrometre (not in metres?): scale the surface first");
  }
  if (input.size() / 3 > (1u << 26)) fail(std::to_string(input.size() / 3) + " triangles: more than 2^26");
  // Degenerate (a repeated corner or no area) and repeated triangles go.
  std::vector<std::array<int, 3>> tris;
  std::map<std::array<int, 3>, int> seen;
  int degenerate = 0, repeated = 0;
  for (size_t k = 0; k + 2 < input.size(); k += 3) {
    const std::array<int, 3> t{input[k], input[k + 1], input[k + 2]};
    const Vec e = (at(positions, t[1]) - at(positions, t[0])).cross(at(positions, t[2]) - at(positions, t[0]));
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || !(e.norm() > 0)) {
      ++degenerate;
      continue;
    }
    std::array<int, 3> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    if (!seen.emplace(sorted, 0).second) {
      ++repeated;
      continue;
    }
    tris.push_back(t);
  }
  if (degenerate) out.repairs.push_back("dropped " + std::to_string(degenerate) + " degenerate triangles (a repeated corner or no area)");
  if (repeated) out.repairs.push_back("dropped " + std::to_string(repeated) + " repeated triangles");
  if (tris.size() < 4) fail("no closed surface: " + std::to_string(tris.size()) + " usable triangles");
  // Edges: each must have exactly two triangles. Holes (edges of one) are closed when asked: each
  // loop of open edges fanned around a new vertex at its centroid.
  std::map<Edge, std::vector<int>> edges;
  const auto countEdges = [&] {
    edges.clear();
    for (size_t t = 0; t < tris.size(); ++t)
      for (int k = 0; k < 3; ++k) edges[std::minmax(tris[t][k], tris[t][(k + 1) % 3])].push_back(static_cast<int>(t));
  };
  countEdges();
  int open = 0, crowded = 0;
  Edge firstOpen{-1, -1}, firstCrowded{-1, -1};
  std::multimap<int, int> openFrom;  // a hole's edges in their triangle's direction: from -> to
  for (const auto& [e, users] : edges) {
    if (users.size() == 1) {
      if (!open++) firstOpen = e;
      const auto& t = tris[users[0]];
      for (int k = 0; k < 3; ++k)
        if (Edge(std::minmax(t[k], t[(k + 1) % 3])) == e) openFrom.emplace(t[k], t[(k + 1) % 3]);
    }
    if (users.size() > 2 && !crowded++) firstCrowded = e;
  }
  if (open && !options.fillHoles)
    fail("not closed: " + std::to_string(open) + " open edges (holes), the first between " + where(positions, firstOpen.first) +
         " and " + where(positions, firstOpen.second) + "; close the holes in a modelling tool");
  if (open && !crowded) {
    int holes = 0;
    double widest = 0;
    while (!openFrom.empty()) {
      std::vector<int> loop{openFrom.begin()->first};
      while (true) {
        const auto next = openFrom.find(loop.back());
        if (next == openFrom.end()) break;
        loop.push_back(next->second);
        openFrom.erase(next);
        if (loop.back() == loop.front()) break;
      }
      if (loop.size() < 4 || loop.back() != loop.front())
        fail("not closed: an open boundary that is not a loop near " + where(positions, loop.front()) + "; close the holes in a modelling tool");
      loop.pop_back();
      Vec centre = Vec::Zero();
      for (int v : loop) centre += at(out.positions, v);
      centre /= double(loop.size());
      for (int v : loop) widest = std::max(widest, 2 * (at(out.positions, v) - centre).norm());
      const int c = static_cast<int>(out.positions.size() / 3);
      out.positions.insert(out.positions.end(), {centre[0], centre[1], centre[2]});
      for (size_t k = 0; k < loop.size(); ++k) tris.push_back({loop[(k + 1) % loop.size()], loop[k], c});
      ++holes;
    }
    char text[160];
    std::snprintf(text, sizeof text, "closed %d holes (%d open edges), the widest %.3g m across, each fanned around its centre", holes,
                  open, widest);
    out.repairs.push_back(text);
    countEdges();
    for (const auto& [e, users] : edges) {
      if (users.size() == 1)
        fail("a hole could not be closed: an open edge remains between " + where(positions, e.first) + " and " +
             where(positions, e.second) + "; close the holes in a modelling tool");
      if (users.size() > 2 && !crowded++) firstCrowded = e;  // a loop through one vertex twice can make one
    }
  }
  if (crowded)
    fail(std::to_string(crowded) + " edges shared by more than two triangles (non-manifold), the first between " +
         where(positions, firstCrowded.first) + " and " + where(positions, firstCrowded.second));
  // Pieces, and a consistent orientation within each (a triangle and its neighbour run their shared edge opposite ways).
  std::vector<int> piece(tris.size(), -1), flipped(tris.size(), 0);
  int pieces = 0, turned = 0;
  for (size_t seed = 0; seed < tris.size(); ++seed) {
    if (piece[seed] >= 0) continue;
    std::vector<int> stack{static_cast<int>(seed)};
    piece[seed] = pieces;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const int a = tris[t][k], b = tris[t][(k + 1) % 3];
        for (int u : edges[std::minmax(a, b)]) {
          if (u == t) continue;
          // u must run b -> a; if it runs a -> b it is turned the other way.
          bool same = false;
          for (int j = 0; j < 3; ++j) same = same || (tris[u][j] == a && tris[u][(j + 1) % 3] == b);
          if (piece[u] < 0) {
            piece[u] = pieces;
            if (same) std::swap(tris[u][1], tris[u][2]), ++turned;
            stack.push_back(u);
          } else if (same) {
            fail("cannot be oriented consistently (a Moebius-like piece), at the edge between " + where(positions, a) + " and " +
                 where(positions, b));
          }
        }
      }
    }
    ++pieces;
  }
  if (turned) out.repairs.push_back("turned " + std::to_string(turned) + " triangles to agree with their neighbours");
  // Each piece outward; the main piece is the largest by volume.
  std::vector<std::vector<std::array<int, 3>>> byPiece(static_cast<size_t>(pieces));
  for (size_t t = 0; t < tris.size(); ++t) byPiece[static_cast<size_t>(piece[t])].push_back(tris[t]);
  std::vector<double> volume(static_cast<size_t>(pieces));
  int inward = 0;
  for (int p = 0; p < pieces; ++p) {
    volume[p] = enclosedVolume(positions, byPiece[p]);
    if (volume[p] < 0) {
      for (auto& t : byPiece[p]) std::swap(t[1], t[2]);
      volume[p] = -volume[p], ++inward;
    }
  }
  if (inward) out.repairs.push_back("turned " + std::to_string(inward) + " inward-facing pieces outward");
  const int main = static_cast<int>(std::max_element(volume.begin(), volume.end()) - volume.begin());
  Eigen::AlignedBox3d box;
  for (const auto& t : byPiece[main])
    for (int v : t) box.extend(at(positions, v));
  // Against the cube of the box's diagonal, not the product of its sides: that is zero for a flat
  // sheet, whose closed holes enclose a rounding error's volume (a flat concave 64-gon passed, and
  // gmsh then ran for ever on it).
  if (!(volume[main] > 1e-9 * std::pow(box.diagonal().norm(), 3)))
    fail("encloses no volume (" + std::to_string(volume[main]) + "): a flat or open sheet, not a solid");
  // Pieces inside the main one, and small ones outside it (decorations: under 5% of its volume),
  // are set aside: a render mesh carries them with the nearest tets.
  int inside = 0, small = 0, apart = 0, firstApart = -1;
  for (int p = 0; p < pieces; ++p) {
    if (p == main) continue;
    if (winding(positions, byPiece[main], at(positions, byPiece[p][0][0])) > 0.5) {
      ++inside;
    } else if (volume[p] < 0.05 * volume[main]) {
      ++small;
    } else if (!apart++) {
      firstApart = byPiece[p][0][0];
    }
  }
  if (apart)
    fail(std::to_string(pieces) + " separate pieces: " + std::to_string(apart) + " outside the largest hold 5% of its volume or more, the first at " +
         where(positions, firstApart) + "; bake each piece on its own, or join them into one closed surface (pieces that overlap: their union)");
  if (inside)
    out.repairs.push_back("set aside " + std::to_string(inside) + " pieces inside the largest (they are carried, not simulated)");
  if (small)
    out.repairs.push_back("set aside " + std::to_string(small) + " small pieces outside the largest (under 5% of its volume: carried, not simulated)");
  out.triangles = byPiece[main];
  out.volume = volume[main];
  const auto crossing = crossings(positions, out.triangles, 1000);
  if (!crossing.empty()) {
    const auto& t = out.triangles[crossing[0].first];
    fail(std::to_string(crossing.size()) + (crossing.size() >= 1000 ? " or more" : "") +
         " pairs of triangles cross each other (self-intersections), the first near " + where(positions, t[0]));
  }
  return out;
}

} // namespace quiver
