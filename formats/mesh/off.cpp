#include "formats/mesh/own_readers.h"

#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "common/mesh_error.h"
#include "formats/mesh/text_cursor.h"

namespace quiver {

namespace {

// The next line that holds anything but a comment, as words.
std::vector<std::string_view> nextLine(TextCursor& in, const char* what) {
  for (;;) {
    if (in.atEnd()) in.token(what);  // fails, naming the file's end
    std::vector<std::string_view> w = words(in.restOfLine());
    if (!w.empty()) return w;
  }
}

double number(const TextCursor& in, std::string_view word, const char* what) {
  double v;
  if (!parseReal(word, v)) in.fail(std::string("expected a number for ") + what + ", found '" + printableToken(word) + "'");
  return v;
}

int64_t whole(const TextCursor& in, std::string_view word, const char* what) {
  int64_t v;
  if (!parseInteger(word, v) || v < 0)
    in.fail(std::string("expected a whole number for ") + what + ", found '" + printableToken(word) + "'");
  return v;
}

} // namespace

PolygonMesh readOff(std::string_view bytes, const std::string& name) {
  TextCursor in(bytes, name, '#');
  std::vector<std::string_view> line = nextLine(in, "the header");
  // [ST][C][N][4][n]OFF, alone on its line or before the counts; the keyword may be left out.
  bool uv = false, normals = false, homogeneous = false, dimension = false;
  int dims = 3;
  std::string_view keyword = line[0];
  if (keyword.size() >= 3 && keyword.substr(keyword.size() - 3) == "OFF") {
    std::string_view prefix = keyword.substr(0, keyword.size() - 3);
    const auto take = [&](std::string_view p) {
      const bool has = prefix.substr(0, p.size()) == p;
      if (has) prefix.remove_prefix(p.size());
      return has;
    };
    uv = take("ST");
    take("C");  // colours, of 1 to 4 components, run to the end of a vertex line: skipped
    normals = take("N"), homogeneous = take("4"), dimension = take("n");
    if (!prefix.empty()) in.fail("unknown header keyword '" + printableToken(keyword) + "' (expected [ST][C][N][4][n]OFF)");
    line.erase(line.begin());
    if (line.empty()) line = nextLine(in, "the counts");
    if (dimension) {
      const int64_t n = whole(in, line[0], "the dimension");
      if (n < 1 || n > 3) in.fail("a dimension of " + std::to_string(n) + "; 1, 2 or 3 are read here");
      dims = static_cast<int>(n);
      line.erase(line.begin());
      if (line.empty()) line = nextLine(in, "the counts");
    }
  }
  if (line.size() < 2 || line.size() > 3) in.fail("expected the counts 'VERTICES FACES [EDGES]'");
  const int64_t vertexCount = whole(in, line[0], "the vertices"), faceCount = whole(in, line[1], "the faces");
  if (line.size() == 3) whole(in, line[2], "the edges");
  PolygonMesh out;
  const size_t needed = static_cast<size_t>(dims + homogeneous + 3 * normals + 2 * uv);
  for (int64_t v = 0; v < vertexCount; ++v) {
    line = nextLine(in, "a vertex");
    if (line.size() < needed)
      in.fail("vertex " + std::to_string(v) + ": " + std::to_string(line.size()) + " numbers, fewer than the " +
              std::to_string(needed) + " the header's keyword asks for");
    double x[3] = {0, 0, 0};
    for (int c = 0; c < dims; ++c) x[c] = number(in, line[c], "a coordinate");
    const double w = homogeneous ? number(in, line[dims], "the homogeneous coordinate") : 1.0;
    for (double c : x) {
      const float position = toFloat(c / w);
      if (!std::isfinite(position)) in.fail("vertex " + std::to_string(v) + ": a coordinate is not a finite float");
      out.positions.push_back(position);
    }
    if (normals)
      for (int c = 0; c < 3; ++c) out.normals.push_back(toFloat(number(in, line[dims + homogeneous + c], "a normal")));
    if (uv)  // after the colours: the line's last two numbers
      for (int c = 0; c < 2; ++c) out.uvs.push_back(toFloat(number(in, line[line.size() - 2 + c], "a texture coordinate")));
  }
  for (int64_t f = 0; f < faceCount; ++f) {
    line = nextLine(in, "a face");
    const int64_t corners = whole(in, line[0], "the face's vertices");
    if (corners < 1 || static_cast<size_t>(corners) > line.size() - 1)
      in.fail("face " + std::to_string(f) + " counts " + std::to_string(corners) + " vertices; its line lists " +
              std::to_string(line.size() - 1) + " numbers");
    out.faceSizes.push_back(static_cast<unsigned>(corners));
    for (int64_t k = 1; k <= corners; ++k) {
      const int64_t index = whole(in, line[k], "a vertex index");
      if (index >= vertexCount)
        in.fail("face " + std::to_string(f) + ": vertex index " + std::to_string(index) + " is out of range [0, " +
                std::to_string(vertexCount) + ")");
      out.indices.push_back(static_cast<unsigned>(index));
    }
  }
  return out;
}

} // namespace quiver
