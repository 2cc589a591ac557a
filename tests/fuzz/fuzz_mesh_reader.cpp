// libFuzzer target: one reader (chosen at compile time by QUIVER_FUZZ_FORMAT) plus validation,
// under AddressSanitizer and UBSan. A clear MeshError is the only acceptable failure; anything
// else (crash, leak, other exception, hang) is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "common/mesh_checks.h"
#include "common/mesh_error.h"
#include "formats/mesh/read_mesh.h"

#define QUIVER_FUZZ_GMSH 1
#define QUIVER_FUZZ_MEDIT 2
#define QUIVER_FUZZ_MFEM 3
#define QUIVER_FUZZ_VEGA 4
#define QUIVER_FUZZ_VTK 5
#define QUIVER_FUZZ_VTU 6
#define QUIVER_FUZZ_TETGEN 7
#define QUIVER_FUZZ_BOU 8

namespace {

quiver::RawMesh parse(std::string_view bytes) {
  using namespace quiver;
#if QUIVER_FUZZ_FORMAT == QUIVER_FUZZ_GMSH
  return parseGmsh(bytes, "fuzz.msh");
#elif QUIVER_FUZZ_FORMAT == QUIVER_FUZZ_MEDIT
  return parseMedit(bytes, "fuzz.mesh");
#elif QUIVER_FUZZ_FORMAT == QUIVER_FUZZ_MFEM
  return parseMfem(bytes, "fuzz.mesh");
#elif QUIVER_FUZZ_FORMAT == QUIVER_FUZZ_VEGA
  return parseVega(bytes, "fuzz.veg");
#elif QUIVER_FUZZ_FORMAT == QUIVER_FUZZ_VTK
  return parseVtkLegacy(bytes, "fuzz.vtk");
#elif QUIVER_FUZZ_FORMAT == QUIVER_FUZZ_VTU
  return parseVtu(bytes, "fuzz.vtu");
#elif QUIVER_FUZZ_FORMAT == QUIVER_FUZZ_TETGEN
  // The input holds the .node text, a NUL byte, then the .ele text.
  size_t split = bytes.find('\0');
  if (split == std::string_view::npos) split = bytes.size();
  return parseTetGen(bytes.substr(0, split), bytes.substr(split == bytes.size() ? split : split + 1), "fuzz.node",
                     "fuzz.ele");
#elif QUIVER_FUZZ_FORMAT == QUIVER_FUZZ_BOU
  parseBou(bytes, "fuzz.bou", 1000);
  return {};
#else
#error "QUIVER_FUZZ_FORMAT must name a reader"
#endif
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    quiver::RawMesh raw = parse(std::string_view(reinterpret_cast<const char*>(data), size));
    if (raw.mesh.tetCount() > 0) quiver::checkMesh(std::move(raw));
  } catch (const quiver::MeshError&) {
  }
  return 0;
}
