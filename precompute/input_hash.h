#pragma once
// A stable 64-bit FNV-1a hash of everything a bake stage depends on, stored with the stage's
// results so that --resume can tell whether they are still valid. Not cryptographic: it guards
// against changed inputs, not against forgery. Each stage's recipe ends with the stage's version
// tag (k<Stage>Version beside the recipe): a stage that computes something else from the same
// inputs gets a new tag, so that --resume recomputes it.
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "formats/model/fnv1a.h"

namespace quiver {

class InputHash {
public:
  InputHash& add(std::string_view bytes) {
    addRaw(bytes.data(), bytes.size());
    return add(static_cast<uint64_t>(bytes.size()));  // length-prefixing keeps "ab","c" apart from "a","bc"
  }
  template <class T, class = std::enable_if_t<std::is_arithmetic_v<T>>>
  InputHash& add(T value) {
    addRaw(&value, sizeof value);
    return *this;
  }
  template <class T>
  InputHash& add(const std::vector<T>& values) {
    for (const T& v : values) add(v);
    return add(static_cast<uint64_t>(values.size()));
  }
  std::string hex() const {
    static const char digits[] = "0123456789abcdef";
    std::string out(16, '0');
    for (int i = 0; i < 16; ++i) out[15 - i] = digits[(state_ >> (4 * i)) & 15];
    return out;
  }

private:
  void addRaw(const void* data, size_t size) { state_ = fnv1a64(data, size, state_); }
  uint64_t state_ = kFnv1aOffsetBasis;
};

} // namespace quiver
