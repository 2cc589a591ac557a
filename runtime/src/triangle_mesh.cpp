#include "triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>

#include "block_carver.h"
#include "vec3.h"

namespace quiver::rt {

namespace {

constexpr int kLeafSize = 4;

void normalise(double v[3]) {
  const double len = std::sqrt(dot3(v, v));
  if (len > 0)
    for (int a = 0; a < 3; ++a) v[a] /= len;
}

// An edge as one triangle runs it: its vertices in ascending order, whether the triangle runs it
// that way, and where (3 * triangle + corner).
struct EdgeUse {
  int lo, hi, slot;
  bool forward;
};

// The closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5) and
// the feature it lies on: 0..2 a corner, 3..5 the edge from corner k - 3 to the next, 6 the face.
int closestOnTriangle(const double p[3], const double a[3], const double b[3], const double c[3], double out[3]) {
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int k = 0; k < 3; ++k) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k];
  const auto at = [&](const double* base, const double* dir, double t, int feature) {
    for (int k = 0; k < 3; ++k) out[k] = base[k] + t * dir[k];
    return feature;
  };
  const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
  if (d1 <= 0 && d2 <= 0) return at(a, ab, 0, 0);
  for (int k = 0; k < 3; ++k) bp[k] = p[k] - b[k];
  const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= 0 && d4 <= d3) return at(b, ab, 0, 1);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return at(a, ab, d1 / (d1 - d3), 3);
  for (int k = 0; k < 3; ++k) cp[k] = p[k] - c[k];
  const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= 0 && d5 <= d6) return at(c, ac, 0, 2);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return at(a, ac, d2 / (d2 - d6), 5);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    double bc[3];
    for (int k = 0; k < 3; ++k) bc[k] = c[k] - b[k];
    return at(b, bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)), 4);
  }
  const double denominator = 1.0 / (va + vb + vc), v = vb * denominator, w = vc * denominator;
  for (int k = 0; k < 3; ++k) out[k] = a[k] + ab[k] * v + ac[k] * w;
  return 6;
}

double boxDistance2(const BvhNode& n, const double p[3]) {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    // std::max, not std::fmax: a libm call each, 8% of a pile's step (0 where p is not finite, too).
    const double d = std::max(0.0, std::max(n.lo[a] - p[a], p[a] - n.hi[a]));
    d2 += d * d;
  }
  return d2;
}

struct Builder {
  const double* vertices;
  const int* triangles;
  const double* centroids;
  int* order;
  BvhNode* nodes;
  int nodeCount = 1;

  // Node `index` over order[first, first + count): its box, then a leaf or two halves split at the
  // median centroid along the longest axis of the centroids' box (depth <= log2(triangles) + 1).
  void build(int index, int first, int count) {
    BvhNode& node = nodes[index];
    double clo[3], chi[3];
    for (int a = 0; a < 3; ++a) node.lo[a] = clo[a] = INFINITY, node.hi[a] = chi[a] = -INFINITY;
    for (int i = first; i < first + count; ++i) {
      const int t = order[i];
      for (int corner = 0; corner < 3; ++corner)
        for (int a = 0; a < 3; ++a) {
          const double x = vertices[3 * triangles[3 * t + corner] + a];
          node.lo[a] = std::fmin(node.lo[a], x), node.hi[a] = std::fmax(node.hi[a], x);
        }
      for (int a = 0; a < 3; ++a)
        clo[a] = std::fmin(clo[a], centroids[3 * t + a]), chi[a] = std::fmax(chi[a], centroids[3 * t + a]);
    }
    if (count <= kLeafSize) {
      node.first = first, node.count = count;
      return;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
    const int half = count / 2;
    std::nth_element(order + first, order + first + half, order + first + count, [&](int x, int y) {
      return centroids[3 * x + axis] < centroids[3 * y + axis];
    });
    const int child = nodeCount;
    nodeCount += 2;
    node.first = child, node.count = 0;
    build(child, first, half);
    build(child + 1, first + half, count - half);
  }
};

struct Layout {
  qv_triangle_mesh* mesh;
  double *vertices, *faceNormals, *edgeNormals, *vertexNormals, *centroids;
  int *triangles, *order;
  BvhNode* nodes;
  EdgeUse* edges;
  size_t bytes;
};

// Measures (block null) or places the mesh's arrays; the edge list and centroids are used while building only.
Layout layOut(int n, int m, char* block) {
  BlockCarver c(block);
  Layout l{};
  l.mesh = c.take<qv_triangle_mesh>(1);
  l.vertices = c.take<double>(3 * size_t(n));
  l.triangles = c.take<int>(3 * size_t(m));
  l.faceNormals = c.take<double>(3 * size_t(m));
  l.edgeNormals = c.take<double>(9 * size_t(m));
  l.vertexNormals = c.take<double>(3 * size_t(n));
  l.order = c.take<int>(m);
  l.nodes = c.take<BvhNode>(2 * size_t(m));
  l.edges = c.take<EdgeUse>(3 * size_t(m));
  l.centroids = c.take<double>(3 * size_t(m));
  l.bytes = c.size();
  return l;
}

template <class... Args>
qv_result fail(char* message, size_t size, const char* format, Args... args) {
  if (message && size) std::snprintf(message, size, format, args...);
  return QV_ERROR_FORMAT;
}

// Pairs every edge with the one triangle that runs it backwards; counts what is not so.
qv_result pairEdges(EdgeUse* edges, int m, char* message, size_t size) {
  std::sort(edges, edges + 3 * size_t(m), [](const EdgeUse& x, const EdgeUse& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.hi != y.hi ? x.hi < y.hi : x.forward < y.forward;
  });
  int open = 0, shared = 0, flipped = 0, example[2] = {-1, -1};
  for (size_t i = 0; i < 3 * size_t(m);) {
    size_t j = i;
    while (j < 3 * size_t(m) && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
    const size_t users = j - i;
    const bool bad = users == 1 ? (++open, true) : users > 2 ? (++shared, true)
                     : edges[i].forward == edges[i + 1].forward ? (++flipped, true) : false;
    if (bad && example[0] < 0) example[0] = edges[i].lo, example[1] = edges[i].hi;
    i = j;
  }
  if (open || shared || flipped)
    return fail(message, size,
                "not a closed, consistently oriented surface: %d edges with one triangle (open), %d shared by more "
                "than two (non-manifold), %d run the same way by both triangles; the first is vertices %d-%d",
                open, shared, flipped, example[0], example[1]);
  return QV_OK;
}

} // namespace

qv_result createTriangleMesh(const double* positions, int n, const int* triangles, int m, const qv_allocator& allocator,
                             qv_triangle_mesh** out, char* message, size_t size) {
  *out = nullptr;
  if (n < 4 || m < 4) return fail(message, size, "a closed surface needs at least 4 vertices and 4 triangles (has %d and %d)", n, m);
  for (size_t i = 0; i < 3 * size_t(n); ++i)
    if (!std::isfinite(positions[i])) return fail(message, size, "vertex %d: coordinate is not finite", int(i / 3));
  for (size_t i = 0; i < 3 * size_t(m); ++i)
    if (triangles[i] < 0 || triangles[i] >= n)
      return fail(message, size, "triangle %d: vertex index %d is not in 0..%d", int(i / 3), triangles[i], n - 1);

  const size_t bytes = layOut(n, m, nullptr).bytes;
  char* block = static_cast<char*>(allocator.allocate(bytes, 64, allocator.user));
  if (!block) return QV_ERROR_OUT_OF_MEMORY;
  const Layout l = layOut(n, m, block);
  qv_triangle_mesh* mesh = new (l.mesh) qv_triangle_mesh{};
  mesh->allocator = allocator;
  const auto reject = [&](qv_result result) {
    destroyTriangleMesh(mesh);
    return result;
  };
  std::memcpy(l.vertices, positions, sizeof(double) * 3 * size_t(n));
  std::memcpy(l.triangles, triangles, sizeof(int) * 3 * size_t(m));
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int v = 0; v < n; ++v)
    for (int a = 0; a < 3; ++a) lo[a] = std::fmin(lo[a], positions[3 * v + a]), hi[a] = std::fmax(hi[a], positions[3 * v + a]);
  const double diagonal2 = (hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]);

  // Enclosed volume by the divergence theorem: negative means the triangles face inward.
  double volume = 0;
  for (int t = 0; t < m; ++t) {
    const double *a = l.vertices + 3 * l.triangles[3 * t], *b = l.vertices + 3 * l.triangles[3 * t + 1],
                 *c = l.vertices + 3 * l.triangles[3 * t + 2];
    double e1[3], e2[3], normal[3];
    for (int k = 0; k < 3; ++k) e1[k] = b[k] - a[k], e2[k] = c[k] - a[k];
    cross3(e1, e2, normal);
    if (!(dot3(normal, normal) > 1e-24 * diagonal2 * diagonal2))
      return reject(fail(message, size, "triangle %d (vertices %d, %d, %d) is degenerate (no area)", t,
                         l.triangles[3 * t], l.triangles[3 * t + 1], l.triangles[3 * t + 2]));
    volume += dot3(a, normal) / 6;
  }
  if (volume < 0)
    for (int t = 0; t < m; ++t) std::swap(l.triangles[3 * t + 1], l.triangles[3 * t + 2]);

  for (int t = 0; t < m; ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = l.triangles[3 * t + k], b = l.triangles[3 * t + (k + 1) % 3];
      l.edges[3 * t + k] = EdgeUse{std::min(a, b), std::max(a, b), 3 * t + k, a < b};
    }
  if (const qv_result r = pairEdges(l.edges, m, message, size); r != QV_OK) return reject(r);

  // Pseudo-normals: faces', the sum of an edge's two faces', and vertices' weighted by their angle.
  std::memset(l.vertexNormals, 0, sizeof(double) * 3 * size_t(n));
  for (int t = 0; t < m; ++t) {
    const int* tri = l.triangles + 3 * t;
    double e1[3], e2[3], *normal = l.faceNormals + 3 * t;
    for (int k = 0; k < 3; ++k) e1[k] = l.vertices[3 * tri[1] + k] - l.vertices[3 * tri[0] + k],
                                e2[k] = l.vertices[3 * tri[2] + k] - l.vertices[3 * tri[0] + k];
    cross3(e1, e2, normal);
    normalise(normal);
    for (int k = 0; k < 3; ++k) {
      const double *p = l.vertices + 3 * tri[k], *p1 = l.vertices + 3 * tri[(k + 1) % 3], *p2 = l.vertices + 3 * tri[(k + 2) % 3];
      double u[3], w[3];
      for (int a = 0; a < 3; ++a) u[a] = p1[a] - p[a], w[a] = p2[a] - p[a];
      const double angle = std::acos(std::fmax(-1.0, std::fmin(1.0, dot3(u, w) / std::sqrt(dot3(u, u) * dot3(w, w)))));
      for (int a = 0; a < 3; ++a) l.vertexNormals[3 * tri[k] + a] += angle * normal[a];
    }
    for (int a = 0; a < 3; ++a) l.centroids[3 * t + a] = (l.vertices[3 * tri[0] + a] + l.vertices[3 * tri[1] + a] + l.vertices[3 * tri[2] + a]) / 3;
  }
  for (int v = 0; v < n; ++v) normalise(l.vertexNormals + 3 * v);
  for (size_t i = 0; i < 3 * size_t(m); i += 2) {  // sorted in pairs by pairEdges
    const int s0 = l.edges[i].slot, s1 = l.edges[i + 1].slot;
    double sum[3];
    for (int a = 0; a < 3; ++a) sum[a] = l.faceNormals[3 * (s0 / 3) + a] + l.faceNormals[3 * (s1 / 3) + a];
    normalise(sum);
    std::memcpy(l.edgeNormals + 3 * s0, sum, sizeof sum);
    std::memcpy(l.edgeNormals + 3 * s1, sum, sizeof sum);
  }

  for (int t = 0; t < m; ++t) l.order[t] = t;
  Builder builder{l.vertices, l.triangles, l.centroids, l.order, l.nodes};
  builder.build(0, 0, m);
  mesh->vertexCount = n, mesh->triangleCount = m, mesh->nodeCount = builder.nodeCount;
  mesh->vertices = l.vertices, mesh->triangles = l.triangles, mesh->faceNormals = l.faceNormals;
  mesh->edgeNormals = l.edgeNormals, mesh->vertexNormals = l.vertexNormals, mesh->order = l.order, mesh->nodes = l.nodes;
  *out = mesh;
  return QV_OK;
}

void destroyTriangleMesh(qv_triangle_mesh* mesh) {
  const qv_allocator allocator = mesh->allocator;
  mesh->~qv_triangle_mesh();
  allocator.release(mesh, allocator.user);
}

} // namespace quiver::rt

bool qv_triangle_mesh::distance(const double p[3], double reach, double& signedDistance, double normal[3], int* triangle,
                                const double* facing, int hint) const {
  using namespace quiver::rt;
  const double rootDistance2 = boxDistance2(nodes[0], p);
  if (rootDistance2 > reach * reach) return false;
  // Nearest first: the nearer child is searched first, and a box farther than the best so far is
  // skipped. Each box's distance is kept with it on the stack, worked out once.
  struct Pending {
    int node;
    double distance2;
  };
  Pending stack[64];
  int depth = 0;
  stack[depth++] = {0, rootDistance2};
  double best = INFINITY, closest[3] = {};
  int bestTriangle = 0, bestFeature = 6;
  const auto measure = [&](int t) {
    if (facing && dot3(faceNormals + 3 * t, facing) >= 0) return;
    const int* tri = triangles + 3 * t;
    double c[3];
    const int feature = closestOnTriangle(p, vertices + 3 * tri[0], vertices + 3 * tri[1], vertices + 3 * tri[2], c);
    const double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    const double d2 = dot3(d, d);
    if (d2 < best) best = d2, bestTriangle = t, bestFeature = feature, std::memcpy(closest, c, sizeof c);
  };
  if (hint >= 0 && hint < triangleCount) measure(hint);
  while (depth) {
    const Pending pending = stack[--depth];
    if (pending.distance2 >= best) continue;
    const BvhNode& node = nodes[pending.node];
    if (node.count) {
      for (int i = node.first; i < node.first + node.count; ++i) measure(order[i]);
      continue;
    }
    const Pending first = {node.first, boxDistance2(nodes[node.first], p)};
    const Pending second = {node.first + 1, boxDistance2(nodes[node.first + 1], p)};
    const bool firstNearer = first.distance2 <= second.distance2;
    stack[depth++] = firstNearer ? second : first;
    stack[depth++] = firstNearer ? first : second;
  }
  if (triangle) *triangle = bestTriangle;
  if (facing) {
    if (best == INFINITY) return false;
    const double* face = faceNormals + 3 * bestTriangle;
    const double d[3] = {p[0] - closest[0], p[1] - closest[1], p[2] - closest[2]};
    signedDistance = dot3(d, face) < 0 ? -std::sqrt(best) : std::sqrt(best);
    std::memcpy(normal, face, 3 * sizeof(double));
    return true;
  }
  const double* pseudo = bestFeature == 6 ? faceNormals + 3 * bestTriangle
                         : bestFeature >= 3 ? edgeNormals + 3 * (3 * bestTriangle + bestFeature - 3)
                                            : vertexNormals + 3 * triangles[3 * bestTriangle + bestFeature];
  const double d[3] = {p[0] - closest[0], p[1] - closest[1], p[2] - closest[2]};
  const double length = std::sqrt(best);
  const double sign = dot3(d, pseudo) < 0 ? -1.0 : 1.0;
  signedDistance = sign * length;
  for (int a = 0; a < 3; ++a) normal[a] = length > 1e-12 ? sign * d[a] / length : pseudo[a];
  return true;
}
