#pragma once
// Reading tetrahedral meshes. The parse* functions work on bytes already in memory (tests and
// fuzzers call them directly); readMeshFile() picks the format from the extension and content.
// None of them validates geometry: see common/mesh_checks.h.
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "common/tet_mesh.h"
#include "common/fixed_vertices.h"
#include "common/mesh_checks.h"
#include "common/mesh_source.h"

namespace quiver {

enum class MeshFormat { Auto, TetGen, Gmsh, Medit, Mfem, Vega, VtkLegacy, Vtu };

RawMesh parseGmsh(std::string_view bytes, const std::string& file);   // .msh 2.2 / 4.1, ASCII or binary
RawMesh parseMedit(std::string_view bytes, const std::string& file);  // .mesh (MeshVersionFormatted, ASCII)
RawMesh parseMfem(std::string_view bytes, const std::string& file);   // .mesh (MFEM mesh v1.0)
RawMesh parseVega(std::string_view bytes, const std::string& file);   // .veg (1-based, *MATERIAL/*SET/*REGION)
RawMesh parseVtkLegacy(std::string_view bytes, const std::string& file);  // .vtk UNSTRUCTURED_GRID
RawMesh parseVtu(std::string_view bytes, const std::string& file);        // .vtu XML UnstructuredGrid
RawMesh parseTetGen(std::string_view nodeBytes, std::string_view eleBytes, const std::string& nodeFile,
                    const std::string& eleFile);  // .node + .ele, 0- or 1-based

// Vega .bou: 1-based vertex numbers separated by commas, blanks or newlines; '#' starts a comment.
// Returns 0-based indices in file vertex order, checked against `vertexCount`.
std::vector<int> parseBou(std::string_view bytes, const std::string& file, int vertexCount);

// The file opened, or MeshError "PATH: cannot open: <reason>" (a directory opens as a stream that
// reads nothing).
std::ifstream openForReading(const std::string& path);
// The whole file, or the same MeshError.
std::string readFileBytes(const std::string& path);

// The extension of `path` in lower case, with its dot (".vtu"), or "" when it has none.
std::string lowerExtension(const std::string& path);

// From the extension (.node/.ele/.msh/.mesh/.veg/.vtk/.vtu) and, for .mesh, the first line.
MeshFormat detectMeshFormat(const std::string& path, std::string_view head);
const char* meshFormatName(MeshFormat f);

// Reads PATH (for TetGen, PATH may name the .node, the .ele or their common stem).
RawMesh readMeshFile(const std::string& path, MeshFormat format = MeshFormat::Auto);

// readMeshFile() then checkMesh().
CheckedMesh loadMesh(const std::string& path, const MeshCheckOptions& options = {},
                     MeshFormat format = MeshFormat::Auto);

// A Vega .bou file as a fixed-vertex list (0-based file vertex numbers); throws MeshError naming
// the file and line of a malformed number. The range is checked against the mesh later.
FileVertexList readBouFile(const std::string& path);

} // namespace quiver
