#include "precompute/archive/xdmf.h"

#include <sstream>
#include <stdexcept>

#include "formats/atomic_file.h"
#include "formats/xml_text.h"

// Layout, chosen for ParaView's XDMF 3 readers (Xdmf3ReaderS and Xdmf3ReaderT) and checked with
// ParaView 5.11's pvpython (values per time step, and Warp By Vector):
// - One Temporal collection per field, time i showing vector i. The reader loads only the grids of
//   the current time, so a large basis is never read whole, the time slider steps through the
//   vectors, and Warp By Vector on the field's array animates them.
// - The reader keeps a grid only when its Time equals the requested time exactly, and drops grids
//   without a Time once the file has times; so every grid carries an integer Time and repeats the
//   mesh's Geometry and Topology (references into the .h5, not copies). A field shorter than the
//   current time shows nothing.
// - Each vector is a node-centred Vector Attribute whose one HDF DataItem selects (1, n, 3) of the
//   (count, n, 3) dataset in XDMF 3's own hyperslab notation, which its writer also produces:
//   "file.h5:/path|start:stride:count:dataspace" = "bake.h5:/modes/vectors|i 0 0:1 1 1:1 n 3:count n 3",
//   with Dimensions equal to the count. The XDMF 2 idiom (a DataItem of ItemType="HyperSlab"
//   wrapping a start/stride/count item and the dataset) is NOT read by the XDMF 3 readers: such an
//   item has no number type until it is read, and vtkXdmf3DataSet skips it ("Skipping
//   unrecognized array type [None]"). ParaView's legacy "XDMF Reader" (XDMF 2) reads the mesh of
//   this file but not the vectors.
// - A field's array carries the field's name ("modes"), so the reader's point-array list has one
//   entry per field to switch it on or off, and Warp By Vector picks it by that name.
// ParaView 5.11 opens a .xmf with Xdmf3ReaderS by default.

namespace quiver {

namespace {

// "/modes/vectors" -> "modes"; a dataset directly under the root is named after itself.
std::string fieldName(const std::string& datasetPath) {
  size_t last = datasetPath.find_last_of('/');
  std::string parent = last == std::string::npos ? std::string() : datasetPath.substr(0, last);
  std::string name = parent.substr(parent.find_last_of('/') + 1);
  return name.empty() ? datasetPath.substr(last + 1) : name;
}

// The document being built, with the archive's name and the mesh's sizes as they appear in it.
struct XdmfText {
  XdmfText(const std::string& h5FileName, int64_t vertexCount, int64_t tetCount)
      : h5_(escapeXml(h5FileName)), n_(std::to_string(vertexCount)), m_(std::to_string(tetCount)) {}

  std::ostringstream out;
  const std::string h5_, n_, m_;

  // `selection` is "" for the whole dataset, else "|start:stride:count:dataspace".
  void heavyItem(const std::string& indent, const std::string& dims, const char* numberType, int precision,
                 const std::string& datasetPath, const std::string& selection = "") {
    out << indent << "<DataItem Dimensions=\"" << dims << "\" NumberType=\"" << numberType << "\" Precision=\""
        << precision << "\" Format=\"HDF\">" << h5_ << ':' << escapeXml(datasetPath) << selection << "</DataItem>\n";
  }

  void mesh(const std::string& indent) {
    out << indent << "<Topology TopologyType=\"Tetrahedron\" NumberOfElements=\"" << m_ << "\">\n";
    heavyItem(indent + "  ", m_ + " 4", "Int", 4, "/mesh/tets");
    out << indent << "</Topology>\n" << indent << "<Geometry GeometryType=\"XYZ\">\n";
    heavyItem(indent + "  ", n_ + " 3", "Float", 8, "/mesh/vertices");
    out << indent << "</Geometry>\n";
  }

  void field(const std::string& datasetPath, int64_t count) {
    const std::string name = escapeXml(fieldName(datasetPath));
    out << "    <Grid Name=\"" << name << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (int64_t i = 0; i < count; ++i) {
      out << "      <Grid Name=\"" << name << "\" GridType=\"Uniform\">\n"
          << "        <Time Value=\"" << i << "\"/>\n";
      mesh("        ");
      out << "        <Attribute Name=\"" << name << "\" AttributeType=\"Vector\" Center=\"Node\">\n";
      heavyItem("          ", "1 " + n_ + " 3", "Float", 8, datasetPath,
                '|' + std::to_string(i) + " 0 0:1 1 1:1 " + n_ + " 3:" + std::to_string(count) + ' ' + n_ + " 3");
      out << "        </Attribute>\n"
          << "      </Grid>\n";
    }
    out << "    </Grid>\n";
  }
};

} // namespace

void writeModesXdmf(const std::string& xmfPath, const std::string& h5FileName, int64_t vertexCount,
                    int64_t tetCount, const std::vector<std::pair<std::string, int64_t>>& fields) {
  // XDMF 3 splits a heavy-data reference at ':' (file from dataset) and '|' (selection).
  if (h5FileName.find_first_of(":|") != std::string::npos)
    throw std::runtime_error(xmfPath + ": cannot refer to " + h5FileName + " from XDMF: its name holds ':' or '|'");
  XdmfText text(h5FileName, vertexCount, tetCount);
  text.out << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n";
  bool anyField = false;
  for (const auto& [datasetPath, count] : fields)
    if (count > 0) {
      text.field(datasetPath, count);
      anyField = true;
    }
  if (!anyField) {
    text.out << "    <Grid Name=\"mesh\" GridType=\"Uniform\">\n";
    text.mesh("      ");
    text.out << "    </Grid>\n";
  }
  text.out << "  </Domain>\n</Xdmf>\n";
  writeFileAtomically(xmfPath, text.out.str());
}

} // namespace quiver
