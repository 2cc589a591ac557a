#pragma once
// The XDMF 3 companion of a bake archive (NAME.xmf beside NAME.h5), so ParaView's XDMF readers
// show the mesh and the archive's vector fields (modes, modal derivatives, basis). The .xmf holds
// only light data: every array is a reference into the HDF5 file. Schema: formats/ARCHIVE.md.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace quiver {

// Writes `xmfPath` atomically. `h5FileName` is the archive as the .xmf refers to it: normally its
// bare file name, the two files sitting side by side; it may not contain ':' or '|'. Geometry is
// "/mesh/vertices" (vertexCount, 3) float64 and topology "/mesh/tets" (tetCount, 4) int32. Each
// field is {dataset path, count} of a (count, vertexCount, 3) float64 dataset; it becomes one
// temporal collection named after the dataset's group ("/modes/vectors" -> "modes") whose time i
// shows vector i as the point array of that name. Fields with count 0 are left out; with no
// fields at all the file shows the bare mesh. Not collective: call it on one rank.
void writeModesXdmf(const std::string& xmfPath, const std::string& h5FileName, int64_t vertexCount,
                    int64_t tetCount, const std::vector<std::pair<std::string, int64_t>>& fields);

} // namespace quiver
