// InputHash: the key --resume trusts to reuse a stage. Checked against FNV-1a written out here,
// and for the properties that keep different inputs apart.
#include <gtest/gtest.h>

#include <cstring>

#include "precompute/input_hash.h"

namespace {

// 64-bit FNV-1a over `bytes`, from its definition.
uint64_t fnv(const std::string& bytes) {
  uint64_t h = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string le64(uint64_t v) {
  std::string s(8, '\0');
  for (int i = 0; i < 8; ++i) s[i] = static_cast<char>(v >> (8 * i));
  return s;
}

std::string hex(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

} // namespace

TEST(InputHash, IsFnv1aOverLengthPrefixedFields) {
  EXPECT_EQ(quiver::InputHash().hex(), hex(fnv("")));
  EXPECT_EQ(quiver::InputHash().add(std::string("mesh")).hex(), hex(fnv("mesh" + le64(4))));
  const double e = 1e6;
  std::string bits(8, '\0');
  std::memcpy(bits.data(), &e, 8);
  EXPECT_EQ(quiver::InputHash().add(e).hex(), hex(fnv(bits)));
  EXPECT_EQ(quiver::InputHash().add(std::vector<int>{7, 8}).hex(),
            hex(fnv(std::string("\x07\0\0\0\x08\0\0\0", 8) + le64(2))));
}

TEST(InputHash, KeepsDifferentInputsApart) {
  using quiver::InputHash;
  const auto h = [](auto&&... parts) {
    InputHash hash;
    (hash.add(parts), ...);
    return hash.hex();
  };
  EXPECT_NE(h(std::string("ab"), std::string("c")), h(std::string("a"), std::string("bc")));
  EXPECT_NE(h(1, 2), h(2, 1));
  EXPECT_NE(h(1), h(1.0));                 // the type's bytes, not the value
  EXPECT_NE(h(std::vector<int>{}), h());   // an empty list still counts
  EXPECT_NE(h(0.0), h(-0.0));
  EXPECT_EQ(h(std::string("modes"), 20), h(std::string("modes"), 20));
  EXPECT_EQ(h().size(), 16u);
}
