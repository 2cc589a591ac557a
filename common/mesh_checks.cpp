#include "common/mesh_checks.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/mesh_error.h"

namespace quiver {

namespace {

constexpr size_t kListed = 5;  // problems named one by one before the rest are only counted

// Collects one kind of problem and reports the first few by element.
class ProblemList {
public:
  explicit ProblemList(std::string kind) : kind_(std::move(kind)) {}
  void add(const std::string& line) {
    if (lines_.size() < kListed) lines_.push_back(line);
    ++count_;
  }
  bool empty() const { return count_ == 0; }
  std::string text(const std::string& advice = "") const {
    std::ostringstream s;
    for (const auto& l : lines_) s << l << "\n";
    if (count_ > lines_.size()) s << "... and " << count_ - lines_.size() << " more\n";
    s << count_ << " " << kind_ << " in total";
    if (!advice.empty()) s << "; " << advice;
    return s.str();
  }
  size_t count() const { return count_; }

private:
  std::string kind_;
  std::vector<std::string> lines_;
  size_t count_ = 0;
};

std::string number(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// 6*sqrt(2)*|V| / l_rms^3: 1 for a regular tet, 0 for a flat one, independent of scale.
double normalisedVolume(const TetMesh& mesh, int t, double signedVol6) {
  const Tet& v = mesh.tets[t];
  double sumSq = 0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) sumSq += (mesh.vertices[v[a]] - mesh.vertices[v[b]]).squaredNorm();
  const double lrms = std::sqrt(sumSq / 6.0);
  if (!(lrms > 0)) return 0;
  return std::sqrt(2.0) * std::abs(signedVol6) / (lrms * lrms * lrms);
}

void checkIndicesAndCoordinates(const RawMesh& raw) {
  const TetMesh& mesh = raw.mesh;
  for (int v = 0; v < mesh.vertexCount(); ++v)
    if (!mesh.vertices[v].allFinite())
      throw MeshError(raw.source.describeVertex(v) + " has a non-finite coordinate");
  for (int t = 0; t < mesh.tetCount(); ++t)
    for (int v : mesh.tets[t])
      if (v < 0 || v >= mesh.vertexCount())
        throw MeshError(raw.source.describeTet(t) + " refers to vertex index " + std::to_string(v) +
                        ", outside [0, " + std::to_string(mesh.vertexCount()) + ")");
  if (mesh.tetCount() == 0) throw MeshError(raw.source.file + ": the mesh has no tetrahedra");
}

void checkDuplicates(const RawMesh& raw) {
  const TetMesh& mesh = raw.mesh;
  std::vector<std::pair<Tet, int>> keys(mesh.tets.size());
  for (int t = 0; t < mesh.tetCount(); ++t) {
    keys[t] = {mesh.tets[t], t};
    std::sort(keys[t].first.begin(), keys[t].first.end());
  }
  std::sort(keys.begin(), keys.end());
  ProblemList dups("duplicate tets");
  for (size_t i = 1; i < keys.size(); ++i)
    if (keys[i].first == keys[i - 1].first)
      dups.add(raw.source.describeTet(keys[i].second) + " has the same four vertices as " +
               raw.source.describeTet(keys[i - 1].second));
  if (!dups.empty()) throw MeshError(dups.text());
}

// Drops vertices no tet uses, keeping the others in file order.
void dropUnreferenced(CheckedMesh& out, const std::string& file) {
  TetMesh& mesh = out.mesh;
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const Tet& t : mesh.tets)
    for (int v : t) used[v] = 1;
  out.loadedVertex.assign(mesh.vertices.size(), -1);
  out.fileVertex.clear();
  for (int v = 0; v < mesh.vertexCount(); ++v)
    if (used[v]) {
      out.loadedVertex[v] = static_cast<int>(out.fileVertex.size());
      out.fileVertex.push_back(v);
    }
  const size_t dropped = mesh.vertices.size() - out.fileVertex.size();
  if (dropped == 0) return;
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(out.fileVertex.size());
  for (int v : out.fileVertex) kept.push_back(mesh.vertices[v]);
  mesh.vertices = std::move(kept);
  for (Tet& t : mesh.tets)
    for (int& v : t) v = out.loadedVertex[v];
  out.warnings.push_back(file + ": dropped " + std::to_string(dropped) +
                         " vertices that no tet uses (vertex numbers are remapped)");
}

} // namespace

CheckedMesh checkMesh(RawMesh raw, const MeshCheckOptions& options) {
  checkIndicesAndCoordinates(raw);
  TetMesh& mesh = raw.mesh;
  if (mesh.tetRegion.size() != mesh.tets.size()) mesh.tetRegion.assign(mesh.tets.size(), 0);

  ProblemList degenerate("degenerate tets"), inverted("inverted tets");
  std::vector<int> toFlip;
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const double vol6 = signedVolume6(mesh, t);
    const double quality = normalisedVolume(mesh, t, vol6);
    if (!(quality >= options.degenerateTolerance)) {
      degenerate.add(raw.source.describeTet(t) + " is degenerate: volume " + number(vol6 / 6) +
                     ", normalised volume " + number(quality) + " (below " + number(options.degenerateTolerance) + ")");
    } else if (vol6 < 0) {
      inverted.add(raw.source.describeTet(t) + " is inverted: signed volume " + number(vol6 / 6));
      toFlip.push_back(t);
    }
  }
  if (!degenerate.empty()) throw MeshError(degenerate.text("remove or repair them"));
  if (!inverted.empty() && !options.fixOrientation)
    throw MeshError(inverted.text("pass --fix-orientation to flip them"));
  checkDuplicates(raw);

  CheckedMesh out;
  out.warnings = std::move(raw.report.warnings);
  out.skippedCells = raw.report.skippedCells;
  for (int t : toFlip) std::swap(mesh.tets[t][1], mesh.tets[t][2]);
  out.flippedTets = static_cast<int>(toFlip.size());
  if (!toFlip.empty()) out.warnings.push_back("flipped " + inverted.text());
  out.mesh = std::move(mesh);
  dropUnreferenced(out, raw.source.file);
  return out;
}

} // namespace quiver
