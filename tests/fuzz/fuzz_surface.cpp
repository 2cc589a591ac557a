// libFuzzer target for the surface readers (Assimp, formats/mesh/read_surface.h) and the checks a
// surface meets before it is tetrahedralized (common/surface_check.h), under AddressSanitizer and
// UBSan (Assimp itself is Debian's, not instrumented: its crashes and hangs still show). The first
// byte picks the format; a MeshError is the only acceptable failure. PLY and OFF go through our
// own readers (formats/mesh/own_readers.h), instrumented here like the rest of our code.
#include <cstddef>
#include <cstdint>

#include "common/mesh_error.h"
#include "common/surface_check.h"
#include "formats/mesh/read_surface.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kFormats[] = {"obj", "stl", "ply", "off", "gltf", "glb"};
  const char* format = kFormats[data[0] % (sizeof kFormats / sizeof *kFormats)];
  try {
    const quiver::SurfaceMesh s = quiver::readSurfaceMemory(data + 1, size - 1, format, "fuzz");
    quiver::checkSurface(s.positions, s.triangles, "fuzz", {true});
  } catch (const quiver::MeshError&) {
  }
  return 0;
}
