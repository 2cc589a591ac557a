#pragma once
// Shortest text that reads back to the same double (round-trip exact), locale-independent.
#include <charconv>
#include <string>

namespace quiver {

inline std::string formatReal(double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

} // namespace quiver
