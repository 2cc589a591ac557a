#pragma once
// What the module's parts share: the owning wrappers of the C API's handles and the checks that
// turn Python arguments into the plain arrays the C API takes (or raise, saying what is wrong).
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "quiver/quiver.h"

namespace quiver_python {

namespace py = pybind11;

// Raised as quiver.FormatError (a ValueError): not a valid .qvr image, or a bad triangle mesh.
struct FormatError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// Raised as OSError: a file that cannot be read.
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Memory with the alignment the C API asks of scratch buffers.
struct AlignedBuffer {
  struct Free {
    void operator()(void* p) const { std::free(p); }
  };
  std::unique_ptr<void, Free> memory;
  AlignedBuffer() = default;
  // Rounded up to a whole number of alignments (never zero), as aligned_alloc wants.
  explicit AlignedBuffer(size_t bytes, size_t alignment = 64)
      : memory(std::aligned_alloc(alignment, (bytes / alignment + 1) * alignment)) {
    if (!memory) throw std::bad_alloc();
  }
  void* get() const { return memory.get(); }
};

class Model {
 public:
  explicit Model(qv_model* model) : model_(model) { qv_model_get_info(model, &info_); }
  ~Model() { qv_model_destroy(model_); }
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;
  const qv_model* get() const { return model_; }
  const qv_model_info& info() const { return info_; }

 private:
  qv_model* model_;
  qv_model_info info_;
};

class TriangleMesh {
 public:
  TriangleMesh(qv_triangle_mesh* mesh, int vertices, int triangles)
      : vertexCount(vertices), triangleCount(triangles), mesh_(mesh) {}
  ~TriangleMesh() { qv_triangle_mesh_destroy(mesh_); }
  TriangleMesh(const TriangleMesh&) = delete;
  TriangleMesh& operator=(const TriangleMesh&) = delete;
  const qv_triangle_mesh* get() const { return mesh_; }

  const int vertexCount, triangleCount;

 private:
  qv_triangle_mesh* mesh_;
};

// A collider as the C API takes it, with the mesh it points to (kept alive by whoever holds it).
struct Collider {
  qv_collider c{};
  std::shared_ptr<TriangleMesh> mesh;
};

// The C API keeps colliders by pointer: an instance or world owns the array it handed over.
struct ColliderSet {
  std::vector<Collider> owned;
  std::vector<qv_collider> raw;
  static ColliderSet from(py::handle colliders);
};

class World;

class Instance {
 public:
  Instance(std::shared_ptr<Model> model, const qv_instance_config& config);
  ~Instance() { qv_instance_destroy(instance_); }
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  // The handle for a call; raises while another thread steps this instance with the GIL released.
  qv_instance* use();
  const qv_instance* use() const { return const_cast<Instance*>(this)->use(); }
  qv_instance* raw() const { return instance_; }

  const std::shared_ptr<Model> model;
  const qv_instance_config config;
  bool busy = false;          // being stepped without the GIL (only read and written with it held)
  const World* world = nullptr;
  ColliderSet colliders;
  AlignedBuffer renderScratch;

 private:
  qv_instance* instance_ = nullptr;
};

// Marks instances busy for the length of a step that releases the GIL; refuses busy ones.
class BusyGuard {
 public:
  explicit BusyGuard(std::vector<Instance*> instances);
  ~BusyGuard();
  BusyGuard(const BusyGuard&) = delete;
  BusyGuard& operator=(const BusyGuard&) = delete;

 private:
  std::vector<Instance*> instances_;
};

class World {
 public:
  explicit World(const qv_world_config& config);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;
  qv_world* get() const { return world_; }
  // The handle for a call; raises while another thread steps this world with the GIL released.
  qv_world* use() const;

  const qv_world_config config;
  bool busy = false;  // being stepped without the GIL (only read and written with it held)
  std::vector<py::object> instances;  // keeps them alive while the world points to them
  ColliderSet colliders;

 private:
  qv_world* world_ = nullptr;
};

// ---- Arguments ----

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;

// A finite float64 array of this shape (-1: any length), converted from any array-like.
Doubles doubles(py::handle value, const std::string& name, const std::vector<py::ssize_t>& shape);
// Three finite numbers.
std::vector<double> vector3(py::handle value, const std::string& name);
// 0-based vertex indices below `vertexCount` (IndexError otherwise), as ints.
std::vector<int> vertexIndices(py::handle value, const std::string& name, int vertexCount);
void checkVertex(long long vertex, int vertexCount);
// A caller's output array: exactly this dtype and shape, C-contiguous and writeable.
py::array outputArray(py::handle out, const py::dtype& dtype, const std::vector<py::ssize_t>& shape, const std::string& name);
std::string shapeText(const std::vector<py::ssize_t>& shape);
std::string typeName(py::handle value);  // the Python type's name, for messages
std::string dtypeName(const py::dtype& dtype);

// A read-only array over `data` whose base is `owner` (which keeps the memory alive); None for null.
py::object view(py::handle owner, const void* data, const py::dtype& dtype, const std::vector<py::ssize_t>& shape);

// The contacts as a structured array laid out as qv_contact (see contactDtype()).
py::dtype contactDtype();

void bindModel(py::module_& m);
void bindInstance(py::module_& m);
void bindColliders(py::module_& m);

} // namespace quiver_python
