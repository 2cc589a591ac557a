#pragma once
// One block of memory, many arrays: each array starts at a 64-byte boundary (cache lines, SIMD).
// Run the same carving code twice, first on a null base to measure the block, then on the block
// to place the arrays, and the size and the layout cannot disagree.
#include <cstddef>

namespace quiver::rt {

class BlockCarver {
public:
  explicit BlockCarver(char* base) : base_(base) {}
  // The next `count` items of T (null while measuring).
  template <class T>
  T* take(size_t count) {
    offset_ = (offset_ + 63) & ~size_t(63);
    T* p = base_ ? reinterpret_cast<T*>(base_ + offset_) : nullptr;
    offset_ += count * sizeof(T);
    return p;
  }
  size_t size() const { return (offset_ + 63) & ~size_t(63); }

private:
  char* base_;
  size_t offset_ = 0;
};

} // namespace quiver::rt
