#include "common/mesh_source.h"

namespace quiver {

std::string MeshSource::describeTet(size_t t) const {
  std::string where = file;
  if (t < tetPosition.size()) {
    switch (positionKind) {
      case SourcePositionKind::Line: where += ":" + std::to_string(tetPosition[t]); break;
      case SourcePositionKind::ByteOffset: where += ": byte " + std::to_string(tetPosition[t]); break;
      case SourcePositionKind::Record: where += ": cell " + std::to_string(tetPosition[t]); break;
    }
  }
  where += ": element " + std::to_string(t < tetFileId.size() ? tetFileId[t] : static_cast<int64_t>(t));
  return where;
}

std::string MeshSource::describeVertex(size_t v) const {
  return file + ": vertex " + std::to_string(v < vertexFileId.size() ? vertexFileId[v] : static_cast<int64_t>(v));
}

} // namespace quiver
