#pragma once
// Bounds-checked reader of binary records inside a file held in memory. Failures throw MeshError
// naming the file and the byte offset.
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

#include "common/mesh_error.h"

namespace quiver {

class ByteCursor {
public:
  // `swapBytes`: the data's byte order differs from this machine's.
  ByteCursor(std::string_view bytes, size_t position, std::string file, bool swapBytes = false)
      : bytes_(bytes), pos_(position), file_(std::move(file)), swap_(swapBytes) {}

  template <class T>
  T read(const char* what) {
    static_assert(std::is_arithmetic_v<T>);
    need(sizeof(T), what);
    T v;
    char raw[sizeof(T)];
    std::memcpy(raw, bytes_.data() + pos_, sizeof(T));
    if (swap_)
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    std::memcpy(&v, raw, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }

  // A count read as type T, bounded by what the remaining bytes could hold at `minBytesEach`.
  template <class T>
  int64_t count(const char* what, int64_t minBytesEach) {
    size_t at = pos_;
    T raw = read<T>(what);
    if constexpr (std::is_signed_v<T>) {
      if (raw < 0) failAt(at, std::string(what) + " " + std::to_string(raw) + " is negative");
    }
    uint64_t n = static_cast<uint64_t>(raw);
    uint64_t remaining = bytes_.size() - pos_;
    if (minBytesEach > 0 && n > remaining / static_cast<uint64_t>(minBytesEach))
      failAt(at, std::string(what) + " " + std::to_string(n) + " cannot fit in the " + std::to_string(remaining) +
                     " bytes left in the file (truncated?)");
    return static_cast<int64_t>(n);
  }

  void need(size_t n, const char* what) const {
    if (n > bytes_.size() - pos_)
      fail(std::string("unexpected end of file while reading ") + what + " (" + std::to_string(n) +
           " bytes needed, " + std::to_string(bytes_.size() - pos_) + " left)");
  }
  void skip(size_t n, const char* what) {
    need(n, what);
    pos_ += n;
  }
  size_t position() const { return pos_; }
  size_t remaining() const { return bytes_.size() - pos_; }
  [[noreturn]] void fail(const std::string& message) const { failAt(pos_, message); }
  [[noreturn]] void failAt(size_t offset, const std::string& message) const {
    throw MeshError(file_ + ": byte " + std::to_string(offset) + ": " + message);
  }

private:
  std::string_view bytes_;
  size_t pos_;
  std::string file_;
  bool swap_;
};

inline bool hostIsLittleEndian() {
  const uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

} // namespace quiver
