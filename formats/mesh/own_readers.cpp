#include "formats/mesh/own_readers.h"

#include <memory>

#include <assimp/BaseImporter.h>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/importerdesc.h>
#include <assimp/scene.h>

#include "common/mesh_error.h"

namespace quiver {

namespace {

// The scene Assimp's post-processing expects: one mesh, one node, one default material. Faces of
// fewer than three vertices are dropped, as the importer drops points and lines.
void fillScene(const PolygonMesh& d, aiScene* scene, const std::string& name) {
  auto mesh = std::make_unique<aiMesh>();
  const unsigned n = static_cast<unsigned>(d.positions.size() / 3);
  mesh->mNumVertices = n;
  mesh->mVertices = new aiVector3D[n];
  for (unsigned v = 0; v < n; ++v) mesh->mVertices[v].Set(d.positions[3 * v], d.positions[3 * v + 1], d.positions[3 * v + 2]);
  if (!d.normals.empty()) {
    mesh->mNormals = new aiVector3D[n];
    for (unsigned v = 0; v < n; ++v) mesh->mNormals[v].Set(d.normals[3 * v], d.normals[3 * v + 1], d.normals[3 * v + 2]);
  }
  if (!d.uvs.empty()) {
    mesh->mTextureCoords[0] = new aiVector3D[n];
    mesh->mNumUVComponents[0] = 2;
    for (unsigned v = 0; v < n; ++v) mesh->mTextureCoords[0][v].Set(d.uvs[2 * v], d.uvs[2 * v + 1], 0);
  }
  unsigned faces = 0;
  for (unsigned size : d.faceSizes) faces += size >= 3;
  if (faces == 0) throw MeshError(name + ": holds no face of three or more vertices");
  mesh->mNumFaces = faces;
  mesh->mFaces = new aiFace[faces];
  size_t next = 0;
  unsigned f = 0;
  for (unsigned size : d.faceSizes) {
    if (size >= 3) {
      aiFace& face = mesh->mFaces[f++];
      face.mNumIndices = size;
      face.mIndices = new unsigned[size];
      for (unsigned k = 0; k < size; ++k) face.mIndices[k] = d.indices[next + k];
      mesh->mPrimitiveTypes |= size == 3 ? aiPrimitiveType_TRIANGLE : aiPrimitiveType_POLYGON;
    }
    next += size;
  }
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh*[1]{mesh.release()};
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial*[1]{new aiMaterial()};
  scene->mRootNode = new aiNode();
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
}

using Reader = PolygonMesh (*)(std::string_view bytes, const std::string& name);

// One of our readers as an Assimp importer of files named *.`extension`.
class OwnImporter : public Assimp::BaseImporter {
public:
  OwnImporter(const char* extension, Reader read, std::string name) : extension_(extension), read_(read), name_(std::move(name)) {
    desc_.mName = "Quiver's reader";
    desc_.mAuthor = desc_.mMaintainer = desc_.mComments = "";
    desc_.mFlags = aiImporterFlags_SupportTextFlavour | aiImporterFlags_SupportBinaryFlavour;
    desc_.mFileExtensions = extension_;
  }

  bool CanRead(const std::string& file, Assimp::IOSystem*, bool) const override { return SimpleExtensionCheck(file, extension_); }
  const aiImporterDesc* GetInfo() const override { return &desc_; }

protected:
  void InternReadFile(const std::string& file, aiScene* scene, Assimp::IOSystem* io) override {
    // Assimp keeps the text of what is thrown here as the Importer's error string.
    const std::unique_ptr<Assimp::IOStream> stream(io->Open(file, "rb"));
    if (!stream) throw MeshError(name_ + ": cannot open");
    std::string bytes(stream->FileSize(), '\0');
    if (!bytes.empty() && stream->Read(bytes.data(), 1, bytes.size()) != bytes.size()) throw MeshError(name_ + ": cannot read");
    fillScene(read_(bytes, name_), scene, name_);
  }

private:
  const char* extension_;
  Reader read_;
  std::string name_;
  aiImporterDesc desc_{};
};

void replace(Assimp::Importer& importer, const char* extension, Reader read, const std::string& name) {
  // Unregistering does not delete: the Importer no longer owns its own importer of the format.
  if (Assimp::BaseImporter* builtIn = importer.GetImporter(extension); builtIn && importer.UnregisterLoader(builtIn) == AI_SUCCESS)
    delete builtIn;
  importer.RegisterLoader(new OwnImporter(extension, read, name));
}

} // namespace

void useOwnReaders(Assimp::Importer& importer, const std::string& name) {
  replace(importer, "ply", readPly, name);
  replace(importer, "off", readOff, name);
}

} // namespace quiver
