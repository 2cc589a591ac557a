// Vega FEM .veg reader/writer (1-based; *VERTICES, *ELEMENTS TET, *MATERIAL ENU, *SET, *REGION)
// and the .bou fixed-vertex list.
#include <map>
#include <string>
#include <unordered_map>

#include "formats/mesh/number_format.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_cursor.h"
#include "formats/mesh/write_mesh.h"

namespace quiver {

namespace {

std::string trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return std::string(s);
}

// Splits "a, b ,c" at commas and trims each field.
std::vector<std::string> commaFields(std::string_view line) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    size_t comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

class VegaReader {
public:
  VegaReader(std::string_view bytes, const std::string& file) : cur_(bytes, file, '#') {
    out_.source.file = file;
    out_.source.positionKind = SourcePositionKind::Line;
  }

  RawMesh read() {
    while (!cur_.atEnd()) {
      std::string_view line = cur_.restOfLine();
      if (line.empty()) continue;
      if (line[0] != '*') cur_.fail("expected a *KEYWORD line, found '" + printableToken(line) + "'");
      std::string_view keyword = line.substr(0, line.find_first_of(" \t"));
      std::string argument = trim(line.substr(keyword.size()));
      if (keyword == "*VERTICES")
        readVertices();
      else if (keyword == "*ELEMENTS")
        readElements();
      else if (keyword == "*MATERIAL")
        readMaterial(argument);
      else if (keyword == "*SET")
        readSet(argument);
      else if (keyword == "*REGION")
        readRegions();
      else if (keyword == "*INCLUDE")
        cur_.fail("*INCLUDE is not supported: merge the included file into this one");
      else
        cur_.fail("unknown keyword '" + printableToken(keyword) + "'");
    }
    if (!sawVertices_) cur_.fail("no *VERTICES section");
    if (!sawElements_) cur_.fail("no *ELEMENTS section");
    assignMaterials();
    return std::move(out_);
  }

private:
  void readVertices() {
    if (sawVertices_) cur_.fail("second *VERTICES section");
    sawVertices_ = true;
    int64_t n = cur_.count("vertex count", 8);
    cur_.integerInRange("dimension", 3, 3);
    cur_.restOfLine();
    out_.mesh.vertices.reserve(n);
    for (int64_t i = 0; i < n; ++i) {
      cur_.integerInRange("vertex number", i + 1, i + 1);
      Eigen::Vector3d x;
      for (int k = 0; k < 3; ++k) x[k] = cur_.finiteReal("vertex coordinate");
      out_.mesh.vertices.push_back(x);
      out_.source.vertexFileId.push_back(i + 1);
    }
  }

  void readElements() {
    if (!sawVertices_) cur_.fail("*ELEMENTS before *VERTICES");
    if (sawElements_) cur_.fail("second *ELEMENTS section");
    sawElements_ = true;
    std::string_view type = cur_.token("element type");
    if (type != "TET" && type != "TETS")
      cur_.fail("element type '" + printableToken(type) + "' is not supported (only TET)");
    int64_t n = cur_.count("element count", 10);
    cur_.integerInRange("vertices per element", 4, 4);
    cur_.restOfLine();
    const int64_t nv = out_.mesh.vertexCount();
    out_.mesh.tets.reserve(n);
    for (int64_t i = 0; i < n; ++i) {
      cur_.integerInRange("element number", i + 1, i + 1);
      int line = cur_.line();
      Tet t;
      for (int k = 0; k < 4; ++k) t[k] = static_cast<int>(cur_.integerInRange("element vertex", 1, nv) - 1);
      out_.mesh.tets.push_back(t);
      out_.source.addTet(line, i + 1);
    }
  }

  void readMaterial(const std::string& name) {
    if (name.empty()) cur_.fail("*MATERIAL needs a name");
    std::vector<std::string> f = commaFields(cur_.restOfLine());
    if (f[0] != "ENU") cur_.fail("material type '" + printableToken(f[0]) + "' is not supported (only ENU)");
    if (f.size() != 4) cur_.fail("ENU material needs 'ENU, density, E, nu'");
    Material m;
    m.name = name;
    double* slots[3] = {&m.density, &m.youngsModulus, &m.poissonRatio};
    for (int k = 0; k < 3; ++k)
      if (!parseReal(f[k + 1], *slots[k])) cur_.fail("material '" + name + "': '" + printableToken(f[k + 1]) + "' is not a number");
    std::string bad = checkMaterial(m);
    if (!bad.empty()) cur_.fail("material '" + name + "': " + bad);
    if (!materialIndex_.emplace(name, static_cast<int>(out_.mesh.materials.size())).second)
      cur_.fail("material '" + name + "' is defined twice");
    out_.mesh.materials.push_back(m);
  }

  // Element numbers, comma separated, over as many lines as precede the next '*' line.
  void readSet(const std::string& name) {
    if (name.empty()) cur_.fail("*SET needs a name");
    std::vector<int>& members = sets_[name];
    while (!cur_.atEnd() && cur_.peekToken().front() != '*') {
      for (const std::string& field : commaFields(cur_.restOfLine())) {
        if (field.empty()) continue;
        int64_t e;
        if (!parseInteger(field, e)) cur_.fail("set '" + name + "': '" + printableToken(field) + "' is not an element number");
        if (e < 1 || e > out_.mesh.tetCount())
          cur_.fail("set '" + name + "': element " + std::to_string(e) + " is out of range [1, " +
                    std::to_string(out_.mesh.tetCount()) + "]");
        members.push_back(static_cast<int>(e - 1));
      }
    }
  }

  // "setName, materialName" lines until the next '*' line.
  void readRegions() {
    while (!cur_.atEnd() && cur_.peekToken().front() != '*') {
      std::vector<std::string> f = commaFields(cur_.restOfLine());
      if (f.size() != 2) cur_.fail("*REGION line needs 'setName, materialName'");
      regions_.push_back({f[0], f[1], cur_.line()});
    }
  }

  void assignMaterials() {
    auto& mesh = out_.mesh;
    mesh.tetRegion.assign(mesh.tets.size(), 0);
    if (mesh.materials.empty()) {
      if (!regions_.empty()) fail(regions_.front().line, "*REGION but no *MATERIAL");
      return;
    }
    mesh.tetMaterial.assign(mesh.tets.size(), -1);
    for (size_t r = 0; r < regions_.size(); ++r) {
      const Region& reg = regions_[r];
      auto m = materialIndex_.find(reg.material);
      if (m == materialIndex_.end()) fail(reg.line, "region uses undefined material '" + reg.material + "'");
      auto assign = [&](int t) {
        mesh.tetMaterial[t] = m->second;
        mesh.tetRegion[t] = static_cast<int>(r) + 1;
      };
      if (reg.set == "allElements") {
        for (int t = 0; t < mesh.tetCount(); ++t) assign(t);
      } else {
        auto s = sets_.find(reg.set);
        if (s == sets_.end()) fail(reg.line, "region uses undefined set '" + reg.set + "'");
        for (int t : s->second) assign(t);
      }
    }
    int64_t uncovered = 0;
    for (int& m : mesh.tetMaterial)
      if (m < 0) {
        m = 0;
        ++uncovered;
      }
    if (uncovered > 0)
      out_.report.warnings.push_back(cur_.file() + ": " + std::to_string(uncovered) +
                                     " elements are in no *REGION; they get the first material '" +
                                     mesh.materials[0].name + "'");
  }

  [[noreturn]] void fail(int line, const std::string& message) const {
    throw MeshError(cur_.file() + ":" + std::to_string(line) + ": " + message);
  }

  struct Region {
    std::string set, material;
    int line;
  };
  TextCursor cur_;
  RawMesh out_;
  bool sawVertices_ = false, sawElements_ = false;
  std::unordered_map<std::string, int> materialIndex_;
  std::unordered_map<std::string, std::vector<int>> sets_;
  std::vector<Region> regions_;
};

} // namespace

RawMesh parseVega(std::string_view bytes, const std::string& file) { return VegaReader(bytes, file).read(); }

std::vector<int> parseBou(std::string_view bytes, const std::string& file, int vertexCount) {
  TextCursor cur(bytes, file, '#');
  std::vector<int> out;
  while (!cur.atEnd()) {
    std::string_view line = cur.restOfLine();
    for (const std::string& field : commaFields(line)) {
      for (size_t start = 0; start < field.size();) {  // blanks separate numbers too
        size_t end = field.find_first_of(" \t", start);
        std::string_view word = std::string_view(field).substr(start, end == std::string::npos ? std::string::npos : end - start);
        start = end == std::string::npos ? field.size() : end + 1;
        if (word.empty()) continue;
        int64_t v;
        if (!parseInteger(word, v)) cur.fail("'" + printableToken(word) + "' is not a vertex number");
        if (v < 1 || v > vertexCount)
          cur.fail("vertex " + std::to_string(v) + " is out of range [1, " + std::to_string(vertexCount) + "] (.bou files are 1-based)");
        out.push_back(static_cast<int>(v - 1));
      }
    }
  }
  return out;
}

std::string formatVega(const TetMesh& mesh) {
  std::string s = "# Vega mesh file written by Quiver.\n# " + std::to_string(mesh.vertices.size()) + " vertices, " +
                  std::to_string(mesh.tets.size()) + " elements\n\n*VERTICES\n" + std::to_string(mesh.vertices.size()) +
                  " 3 0 0\n";
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto& x = mesh.vertices[v];
    s += std::to_string(v + 1) + " " + formatReal(x.x()) + " " + formatReal(x.y()) + " " + formatReal(x.z()) + "\n";
  }
  s += "\n*ELEMENTS\nTET\n" + std::to_string(mesh.tets.size()) + " 4 0\n";
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    s += std::to_string(t + 1);
    for (int v : mesh.tets[t]) s += " " + std::to_string(v + 1);
    s += "\n";
  }
  if (mesh.tetMaterial.empty()) return s;
  for (const Material& m : mesh.materials)
    s += "\n*MATERIAL " + m.name + "\nENU, " + formatReal(m.density) + ", " + formatReal(m.youngsModulus) + ", " +
         formatReal(m.poissonRatio) + "\n";
  // One set per material, named after it, listing its elements.
  for (size_t m = 0; m < mesh.materials.size(); ++m) {
    s += "\n*SET set_" + mesh.materials[m].name + "\n";
    int onLine = 0;
    for (size_t t = 0; t < mesh.tets.size(); ++t)
      if (mesh.tetMaterial[t] == static_cast<int>(m)) s += std::to_string(t + 1) + (++onLine % 16 == 0 ? ",\n" : ", ");
    s += "\n";
  }
  s += "\n*REGION\n";
  for (const Material& m : mesh.materials) s += "set_" + m.name + ", " + m.name + "\n";
  return s;
}

} // namespace quiver
