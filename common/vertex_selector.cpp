#include "common/vertex_selector.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <stdexcept>

namespace quiver {

namespace {

class Parser {
public:
  explicit Parser(const std::string& s) : s_(s) {}
  void skipBlanks() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool done() {
    skipBlanks();
    return pos_ >= s_.size();
  }
  bool accept(const std::string& word) {
    skipBlanks();
    if (s_.compare(pos_, word.size(), word) != 0) return false;
    pos_ += word.size();
    return true;
  }
  double number() {
    skipBlanks();
    size_t start = pos_;
    if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
    while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '.' ||
                                ((s_[pos_] == '-' || s_[pos_] == '+') && (s_[pos_ - 1] == 'e' || s_[pos_ - 1] == 'E'))))
      ++pos_;
    const char* first = s_.data() + start + (s_[start] == '+' ? 1 : 0);
    double v = 0;
    auto [end, ec] = std::from_chars(first, s_.data() + pos_, v);
    if (ec != std::errc() || end != s_.data() + pos_ || !std::isfinite(v)) {
      pos_ = start;
      fail("expected a number");
    }
    return v;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument("vertex selector '" + s_ + "': " + what + " at character " + std::to_string(pos_ + 1) +
                                " (expected e.g. \"x<0.01\", \"y>=max-1e-3 & z<0.5\" or \"box:x0,y0,z0,x1,y1,z1\")");
  }

private:
  const std::string& s_;
  size_t pos_ = 0;
};

} // namespace

VertexSelector::VertexSelector(const std::string& expression) : expression_(expression) {
  Parser p(expression_);
  if (p.accept("box:")) {
    double c[6];
    for (int k = 0; k < 6; ++k) {
      c[k] = p.number();
      if (k < 5 && !p.accept(",")) p.fail("expected ','");
    }
    for (int a = 0; a < 3; ++a) {
      if (c[a] > c[a + 3]) p.fail("box minimum exceeds maximum");
      clauses_.push_back({a, 3, -1, c[a]});
      clauses_.push_back({a, 1, -1, c[a + 3]});
    }
  } else {
    do {
      Clause c{};
      if (p.accept("x")) c.axis = 0;
      else if (p.accept("y")) c.axis = 1;
      else if (p.accept("z")) c.axis = 2;
      else p.fail("expected x, y or z");
      if (p.accept("<=")) c.op = 1;
      else if (p.accept("<")) c.op = 0;
      else if (p.accept(">=")) c.op = 3;
      else if (p.accept(">")) c.op = 2;
      else p.fail("expected <, <=, > or >=");
      c.relativeTo = p.accept("min") ? 0 : p.accept("max") ? 1 : -1;
      if (c.relativeTo < 0) c.value = p.number();
      else if (p.accept("+")) c.value = p.number();
      else if (p.accept("-")) c.value = -p.number();
      clauses_.push_back(c);
    } while (p.accept("&"));
  }
  if (!p.done()) p.fail("unexpected text");
}

std::vector<int> VertexSelector::select(const TetMesh& mesh) const {
  const auto box = boundingBox(mesh);
  std::vector<int> out;
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    bool keep = true;
    for (const Clause& c : clauses_) {
      const double ref = c.relativeTo < 0 ? 0.0 : box[c.relativeTo][c.axis];
      const double bound = ref + c.value, x = mesh.vertices[v][c.axis];
      const bool ok = c.op == 0 ? x < bound : c.op == 1 ? x <= bound : c.op == 2 ? x > bound : x >= bound;
      keep = keep && ok;
    }
    if (keep) out.push_back(v);
  }
  return out;
}

} // namespace quiver
