#pragma once
// 64-bit FNV-1a (Fowler-Noll-Vo): the checksum of the .qvr format (QVR.md). Standard library only.
// It detects accidental corruption (any single changed byte always changes it); it is not
// cryptographic and does not guard against forgery.
#include <cstddef>
#include <cstdint>

namespace quiver {

constexpr uint64_t kFnv1aOffsetBasis = 0xcbf29ce484222325ull;
constexpr uint64_t kFnv1aPrime = 0x100000001b3ull;

// The hash of `size` bytes, continuing from `state`: hashing a and then b with the result of a as
// the state equals hashing a followed by b.
inline uint64_t fnv1a64(const void* data, size_t size, uint64_t state = kFnv1aOffsetBasis) noexcept {
  const unsigned char* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) state = (state ^ bytes[i]) * kFnv1aPrime;
  return state;
}

} // namespace quiver
