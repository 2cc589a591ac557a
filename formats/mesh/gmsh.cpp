// Gmsh .msh reader (2.2 and 4.1, ASCII and binary) and 4.1 ASCII writer.
// Vertices keep the file's node order; node tags may be sparse and are mapped to indices.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>

#include "formats/mesh/byte_cursor.h"
#include "formats/mesh/number_format.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_cursor.h"
#include "formats/mesh/write_mesh.h"

namespace quiver {

namespace {

constexpr int kTet4 = 4;
constexpr int kTet10 = 11;

// Nodes per element for Gmsh's element types (0: unknown type).
int nodesPerElement(int64_t type) {
  static const int table[] = {0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4, 5, 6, 20, 35, 56};
  if (type >= 0 && type < static_cast<int64_t>(std::size(table))) return table[type];
  if (type == 92) return 64;
  if (type == 93) return 125;
  return 0;
}

// Reads the numbers of one section either as ASCII tokens or as binary values, so the 4.1
// reader has a single code path for both encodings.
class FieldReader {
public:
  FieldReader(TextCursor& text, bool binary, bool swap, int sizeTBytes)
      : text_(text), binary_(binary), sizeT_(sizeTBytes),
        bytes_(text.text(), text.position(), text.file(), swap) {}

  int64_t readInt(const char* what) { return binary_ ? bytes_.read<int32_t>(what) : text_.integer(what); }
  int64_t readSize(const char* what) {
    if (!binary_) return text_.integer(what);
    return sizeT_ == 8 ? static_cast<int64_t>(bytes_.read<uint64_t>(what)) : bytes_.read<uint32_t>(what);
  }
  double readDouble(const char* what) { return binary_ ? bytes_.read<double>(what) : text_.real(what); }
  double readCoordinate(const char* what) {
    size_t at = bytes_.position();
    double v = readDouble(what);
    if (!std::isfinite(v)) {
      if (binary_) bytes_.failAt(at, std::string(what) + " is not finite");
      text_.fail(std::string(what) + " is not finite");
    }
    return v;
  }
  // A size_t count bounded by the bytes left (ASCII items take at least 2 bytes each per field).
  int64_t readCount(const char* what, int64_t minBytesEach) {
    if (!binary_) return text_.count(what, minBytesEach);
    return sizeT_ == 8 ? bytes_.count<uint64_t>(what, minBytesEach) : bytes_.count<uint32_t>(what, minBytesEach);
  }
  int64_t position() const { return binary_ ? static_cast<int64_t>(bytes_.position()) : text_.line(); }
  [[noreturn]] void fail(const std::string& message) const {
    if (binary_) bytes_.fail(message);
    text_.fail(message);
  }
  // Hands the position back to the text cursor after binary data.
  void finish() {
    if (binary_) text_.seek(bytes_.position());
  }
  bool binary() const { return binary_; }

private:
  TextCursor& text_;
  bool binary_;
  int sizeT_;
  ByteCursor bytes_;
};

class GmshReader {
public:
  GmshReader(std::string_view bytes, const std::string& file) : cur_(bytes, file) {
    out_.source.file = file;
  }

  RawMesh read() {
    readHeader();
    bool sawNodes = false, sawElements = false;
    while (!cur_.atEnd()) {
      std::string_view section = cur_.token("section name");
      if (section == "$Entities") {
        readEntities();
      } else if (section == "$Nodes") {
        if (sawNodes) cur_.fail("second $Nodes section (only one is supported)");
        version_ >= 4 ? readNodes41() : readNodes22();
        sawNodes = true;
      } else if (section == "$Elements") {
        if (!sawNodes) cur_.fail("$Elements before $Nodes");
        if (sawElements) cur_.fail("second $Elements section (only one is supported)");
        version_ >= 4 ? readElements41() : readElements22();
        sawElements = true;
      } else if (section.size() > 1 && section[0] == '$' && section.substr(0, 4) != "$End") {
        skipSection(section);
      } else {
        cur_.fail("expected a section such as $Nodes, found '" + printableToken(section) + "'");
      }
    }
    if (!sawNodes) cur_.fail("no $Nodes section");
    if (!sawElements) cur_.fail("no $Elements section");
    if (out_.report.skippedCells > 0)
      out_.report.warnings.push_back(cur_.file() + ": skipped " + std::to_string(out_.report.skippedCells) +
                                     " non-tetrahedral elements");
    if (tet10_ > 0)
      out_.report.warnings.push_back(cur_.file() + ": " + std::to_string(tet10_) +
                                     " 10-node tets reduced to their 4 corner vertices");
    return std::move(out_);
  }

private:
  void readHeader() {
    cur_.expect("$MeshFormat");
    std::string_view v = cur_.token("format version");
    if (v == "2.2" || v == "2.1" || v == "2")
      version_ = 2;
    else if (v == "4.1")
      version_ = 4;
    else
      cur_.fail("unsupported Gmsh format version '" + printableToken(v) + "' (2.2 and 4.1 are supported)");
    binary_ = cur_.integerInRange("file type", 0, 1) == 1;
    sizeT_ = static_cast<int>(cur_.integer("data size"));
    if (sizeT_ != 4 && sizeT_ != 8) cur_.fail("data size " + std::to_string(sizeT_) + " is not 4 or 8");
    cur_.restOfLine();
    out_.source.positionKind = binary_ ? SourcePositionKind::ByteOffset : SourcePositionKind::Line;
    if (binary_) {
      ByteCursor b(cur_.text(), cur_.position(), cur_.file());
      int32_t one = b.read<int32_t>("endianness marker");
      if (one == 0x01000000)
        swap_ = true;
      else if (one != 1)
        b.fail("endianness marker is " + std::to_string(one) + ", not 1");
      cur_.seek(b.position());
    }
    cur_.expect("$EndMeshFormat");
  }

  void skipSection(std::string_view section) {
    std::string end = "\n$End" + std::string(section.substr(1));
    size_t at = cur_.text().find(end, cur_.position());
    if (at == std::string_view::npos) cur_.fail("section " + std::string(section) + " has no " + end.substr(1));
    cur_.seek(at + end.size());
  }

  void startBinary() { cur_.restOfLine(); }  // binary data starts after the section line's newline

  void readEntities() {
    if (binary_) startBinary();
    FieldReader in(cur_, binary_, swap_, sizeT_);
    int64_t counts[4];
    for (auto& c : counts) c = in.readCount("entity count", 4);
    for (int dim = 0; dim < 4; ++dim)
      for (int64_t e = 0; e < counts[dim]; ++e) {
        int64_t tag = in.readInt("entity tag");
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) in.readDouble("entity bounding box");
        int64_t nPhysical = in.readCount("physical tag count", 2);
        std::optional<int64_t> physical;
        for (int64_t p = 0; p < nPhysical; ++p) {
          int64_t ph = in.readInt("physical tag");
          if (!physical) physical = ph;
        }
        if (dim > 0) {
          int64_t nBounding = in.readCount("bounding entity count", 2);
          for (int64_t b = 0; b < nBounding; ++b) in.readInt("bounding entity tag");
        }
        if (dim == 3 && physical) volumePhysical_[tag] = *physical;
      }
    in.finish();
    cur_.expect("$EndEntities");
  }

  void addNode(int64_t tag, const Eigen::Vector3d& x, FieldReader* in) {
    auto [it, inserted] = nodeIndex_.emplace(tag, out_.mesh.vertexCount());
    if (!inserted) {
      std::string msg = "node tag " + std::to_string(tag) + " appears twice";
      if (in) in->fail(msg);
      cur_.fail(msg);
    }
    out_.mesh.vertices.push_back(x);
    out_.source.vertexFileId.push_back(tag);
  }

  void readNodes22() {
    int64_t n = cur_.count("node count", binary_ ? 28 : 8);
    out_.mesh.vertices.reserve(n);
    if (binary_) {
      startBinary();
      FieldReader in(cur_, true, swap_, sizeT_);
      for (int64_t i = 0; i < n; ++i) {
        int64_t tag = in.readInt("node tag");
        Eigen::Vector3d x;
        for (int k = 0; k < 3; ++k) x[k] = in.readCoordinate("node coordinate");
        addNode(tag, x, &in);
      }
      in.finish();
    } else {
      for (int64_t i = 0; i < n; ++i) {
        int64_t tag = cur_.integer("node tag");
        Eigen::Vector3d x;
        for (int k = 0; k < 3; ++k) x[k] = cur_.finiteReal("node coordinate");
        addNode(tag, x, nullptr);
      }
    }
    cur_.expect("$EndNodes");
  }

  void readNodes41() {
    if (binary_) startBinary();
    FieldReader in(cur_, binary_, swap_, sizeT_);
    int64_t blocks = in.readCount("node block count", 4);
    int64_t n = in.readCount("node count", binary_ ? 32 : 8);
    in.readSize("minimum node tag");
    in.readSize("maximum node tag");
    out_.mesh.vertices.reserve(n);
    std::vector<int64_t> tags;
    for (int64_t b = 0; b < blocks; ++b) {
      int64_t entityDim = in.readInt("entity dimension");
      in.readInt("entity tag");
      int64_t parametric = in.readInt("parametric flag");
      int64_t inBlock = in.readCount("nodes in block", binary_ ? 32 : 8);
      if (entityDim < 0 || entityDim > 3) in.fail("entity dimension " + std::to_string(entityDim) + " is not 0..3");
      tags.resize(inBlock);
      for (auto& t : tags) t = in.readSize("node tag");
      for (int64_t t : tags) {
        Eigen::Vector3d x;
        for (int k = 0; k < 3; ++k) x[k] = in.readCoordinate("node coordinate");
        if (parametric) for (int64_t k = 0; k < entityDim; ++k) in.readDouble("parametric coordinate");
        addNode(t, x, &in);
      }
    }
    if (out_.mesh.vertexCount() != n)
      in.fail("$Nodes declares " + std::to_string(n) + " nodes but its blocks hold " +
              std::to_string(out_.mesh.vertexCount()));
    in.finish();
    cur_.expect("$EndNodes");
  }

  // Adds one element of `type` whose node tags are in `nodes`; other element types are counted.
  void addElement(int64_t type, int64_t tag, const int64_t* nodes, int64_t region, int64_t position,
                  FieldReader* in) {
    if (type != kTet4 && type != kTet10) {
      ++out_.report.skippedCells;
      return;
    }
    if (type == kTet10) ++tet10_;
    Tet t;
    for (int k = 0; k < 4; ++k) {
      auto it = nodeIndex_.find(nodes[k]);
      if (it == nodeIndex_.end()) {
        std::string msg = "element " + std::to_string(tag) + " refers to node " + std::to_string(nodes[k]) +
                          ", which $Nodes does not define";
        if (in) in->fail(msg);
        cur_.fail(msg);
      }
      t[k] = it->second;
    }
    out_.mesh.tets.push_back(t);
    out_.mesh.tetRegion.push_back(static_cast<int>(std::clamp<int64_t>(region, INT32_MIN, INT32_MAX)));
    out_.source.addTet(position, tag);
  }

  int checkedNodeCount(int64_t type) {
    int nn = nodesPerElement(type);
    if (nn == 0) cur_.fail("element type " + std::to_string(type) + " is not a Gmsh element type this reader knows");
    return nn;
  }

  void readElements22() {
    int64_t n = cur_.count("element count", binary_ ? 12 : 8);
    int64_t nodes[125];
    if (!binary_) {
      for (int64_t i = 0; i < n; ++i) {
        int64_t tag = cur_.integer("element tag");
        int line = cur_.line();
        int64_t type = cur_.integer("element type");
        int nn = checkedNodeCount(type);
        int64_t ntags = cur_.integerInRange("tag count", 0, 1000);
        int64_t region = 0;
        for (int64_t k = 0; k < ntags; ++k) {
          int64_t v = cur_.integer("element tag value");
          if (k == 0) region = v;
        }
        for (int k = 0; k < nn; ++k) nodes[k] = cur_.integer("element node");
        addElement(type, tag, nodes, region, line, nullptr);
      }
    } else {
      startBinary();
      FieldReader in(cur_, true, swap_, sizeT_);
      int64_t done = 0;
      while (done < n) {
        int64_t type = in.readInt("element type");
        int64_t count = in.readInt("elements in block");
        int64_t ntags = in.readInt("tag count");
        int nn = nodesPerElement(type);
        if (nn == 0) in.fail("element type " + std::to_string(type) + " is not a Gmsh element type this reader knows");
        if (count <= 0 || count > n - done) in.fail("element block size " + std::to_string(count) + " is invalid");
        if (ntags < 0 || ntags > 1000) in.fail("tag count " + std::to_string(ntags) + " is invalid");
        for (int64_t e = 0; e < count; ++e) {
          int64_t position = in.position();
          int64_t tag = in.readInt("element tag");
          int64_t region = 0;
          for (int64_t k = 0; k < ntags; ++k) {
            int64_t v = in.readInt("element tag value");
            if (k == 0) region = v;
          }
          for (int k = 0; k < nn; ++k) nodes[k] = in.readInt("element node");
          addElement(type, tag, nodes, region, position, &in);
        }
        done += count;
      }
      in.finish();
    }
    cur_.expect("$EndElements");
  }

  void readElements41() {
    if (binary_) startBinary();
    FieldReader in(cur_, binary_, swap_, sizeT_);
    int64_t blocks = in.readCount("element block count", 4);
    int64_t n = in.readCount("element count", binary_ ? 16 : 4);
    in.readSize("minimum element tag");
    in.readSize("maximum element tag");
    out_.mesh.tets.reserve(n);
    int64_t nodes[125];
    int64_t total = 0;
    for (int64_t b = 0; b < blocks; ++b) {
      in.readInt("entity dimension");
      int64_t entity = in.readInt("entity tag");
      int64_t type = in.readInt("element type");
      int64_t count = in.readCount("elements in block", binary_ ? 16 : 4);
      int nn = nodesPerElement(type);
      if (nn == 0) in.fail("element type " + std::to_string(type) + " is not a Gmsh element type this reader knows");
      auto phys = volumePhysical_.find(entity);
      int64_t region = phys == volumePhysical_.end() ? 0 : phys->second;
      for (int64_t e = 0; e < count; ++e) {
        int64_t before = in.position();
        int64_t tag = in.readSize("element tag");
        int64_t position = in.binary() ? before : in.position();  // binary: record start; ASCII: its line
        for (int k = 0; k < nn; ++k) nodes[k] = in.readSize("element node");
        addElement(type, tag, nodes, region, position, &in);
      }
      total += count;
    }
    if (total != n)
      in.fail("$Elements declares " + std::to_string(n) + " elements but its blocks hold " + std::to_string(total));
    in.finish();
    cur_.expect("$EndElements");
  }

  TextCursor cur_;
  RawMesh out_;
  int version_ = 0;
  bool binary_ = false;
  bool swap_ = false;
  int sizeT_ = 8;
  int64_t tet10_ = 0;
  std::unordered_map<int64_t, int> nodeIndex_;
  std::unordered_map<int64_t, int64_t> volumePhysical_;  // volume entity tag -> first physical tag
};

} // namespace

RawMesh parseGmsh(std::string_view bytes, const std::string& file) { return GmshReader(bytes, file).read(); }

std::string formatGmsh(const TetMesh& mesh) {
  // One volume entity per distinct region (region 0: no physical group); one element block per
  // run of equal regions, so the tets keep their order.
  auto regionOf = [&](int t) { return mesh.tetRegion.empty() ? 0 : mesh.tetRegion[t]; };
  std::map<int, int> entityOf;
  std::map<int, std::array<Eigen::Vector3d, 2>> boxOf;
  for (int t = 0; t < mesh.tetCount(); ++t) {
    auto [it, fresh] = entityOf.emplace(regionOf(t), static_cast<int>(entityOf.size()) + 1);
    for (int v : mesh.tets[t]) {
      auto& box = boxOf[it->first];
      box[0] = fresh ? mesh.vertices[v] : box[0].cwiseMin(mesh.vertices[v]);
      box[1] = fresh ? mesh.vertices[v] : box[1].cwiseMax(mesh.vertices[v]);
      fresh = false;
    }
  }
  if (entityOf.empty()) {
    entityOf[0] = 1;
    boxOf[0] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  }
  std::string s = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 " + std::to_string(entityOf.size()) + "\n";
  for (const auto& [region, entity] : entityOf) {
    s += std::to_string(entity);
    for (const auto& corner : boxOf[region])
      for (int k = 0; k < 3; ++k) s += " " + formatReal(corner[k]);
    s += region != 0 ? " 1 " + std::to_string(region) + " 0\n" : " 0 0\n";
  }
  const size_t n = mesh.vertices.size();
  s += "$EndEntities\n$Nodes\n1 " + std::to_string(n) + " 1 " + std::to_string(n) + "\n3 " +
       std::to_string(entityOf.begin()->second) + " 0 " + std::to_string(n) + "\n";
  for (size_t v = 0; v < n; ++v) s += std::to_string(v + 1) + "\n";
  for (const auto& x : mesh.vertices) s += formatReal(x.x()) + " " + formatReal(x.y()) + " " + formatReal(x.z()) + "\n";

  std::vector<std::pair<int, int>> runs;  // [first tet, end) of equal regions
  for (int t = 0; t < mesh.tetCount(); ++t)
    if (t == 0 || regionOf(t) != regionOf(t - 1)) runs.emplace_back(t, t);
  for (size_t r = 0; r < runs.size(); ++r) runs[r].second = r + 1 < runs.size() ? runs[r + 1].first : mesh.tetCount();
  s += "$EndNodes\n$Elements\n" + std::to_string(runs.size()) + " " + std::to_string(mesh.tets.size()) + " 1 " +
       std::to_string(mesh.tets.size()) + "\n";
  for (const auto& [first, last] : runs) {
    s += "3 " + std::to_string(entityOf[regionOf(first)]) + " 4 " + std::to_string(last - first) + "\n";
    for (int t = first; t < last; ++t) {
      s += std::to_string(t + 1);
      for (int v : mesh.tets[t]) s += " " + std::to_string(v + 1);
      s += "\n";
    }
  }
  s += "$EndElements\n";
  return s;
}

} // namespace quiver
