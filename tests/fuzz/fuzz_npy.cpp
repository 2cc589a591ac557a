// libFuzzer target for the .npy reader, under AddressSanitizer and UBSan. A std::runtime_error is
// the only acceptable failure. Whatever parses must also survive formatNpy and parse back to the
// same shape and the same bits; a mismatch aborts.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "formats/npy.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  quiver::NpyArray array;
  try {
    array = quiver::parseNpy(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.npy");
  } catch (const std::runtime_error&) {
    return 0;
  }
  const quiver::NpyArray again = quiver::parseNpy(quiver::formatNpy(array.shape, array.data.data()), "again.npy");
  const size_t bytes = array.data.size() * sizeof(double);
  if (again.shape != array.shape || again.data.size() != array.data.size() ||
      (bytes > 0 && std::memcmp(again.data.data(), array.data.data(), bytes) != 0))
    std::abort();
  return 0;
}
