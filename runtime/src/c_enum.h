#pragma once
// The int a C caller stored in an enum field of the API. Any int is valid C there, but in C++
// loading an enum outside its enumerators' range is undefined (UBSan stops on it), so the
// validators of untrusted structs read the int.
#include <cstring>

namespace quiver::rt {

template <class E>
int cEnumValue(const E& e) {
  static_assert(sizeof(E) == sizeof(int), "the C API's enums are ints");
  int value;
  std::memcpy(&value, &e, sizeof value);
  return value;
}

} // namespace quiver::rt
