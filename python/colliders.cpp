// Colliders (quiver.Plane, Sphere, Box, Capsule, MeshCollider) and quiver.TriangleMesh. A collider
// is an immutable description, checked when made; Instance.set_colliders and World.set_colliders
// copy the list into the array the C API keeps by pointer, so a moved collider is a new list.
#include <cmath>
#include <limits>
#include <string>

#include "bindings.h"

namespace quiver_python {

namespace {

struct Plane : Collider {};
struct Sphere : Collider {};
struct Box : Collider {};
struct Capsule : Collider {};
struct MeshCollider : Collider {};

void checkPositive(double value, const char* name) {
  if (!(value > 0) || !std::isfinite(value))
    throw py::value_error(std::string(name) + " must be positive and finite, got " + std::to_string(value));
}

// The fields every collider has; `data` and the mesh are the shape's.
template <class Shape>
Shape common(qv_collider_type type, double friction, double restitution, py::handle velocity, py::handle angularVelocity) {
  if (!(friction >= 0) || !std::isfinite(friction)) throw py::value_error("friction must be >= 0 and finite");
  if (!(restitution >= 0 && restitution <= 1)) throw py::value_error("restitution must be between 0 and 1");
  Shape shape;
  shape.c.type = type;
  shape.c.friction = friction;
  shape.c.restitution = restitution;
  const std::vector<double> v = vector3(velocity, "velocity"), w = vector3(angularVelocity, "angular_velocity");
  for (int a = 0; a < 3; ++a) {
    shape.c.velocity[a] = v[a];
    shape.c.angular_velocity[a] = w[a];
  }
  return shape;
}

void put(qv_collider& c, int at, const std::vector<double>& values) {
  for (size_t i = 0; i < values.size(); ++i) c.data[at + i] = values[i];
}

py::array_t<double> slice(const double* values, py::ssize_t count) {
  py::array_t<double> out(count);
  for (py::ssize_t i = 0; i < count; ++i) out.mutable_data()[i] = values[i];
  return out;
}

const char* shapeName(qv_collider_type type) {
  switch (type) {
    case QV_COLLIDER_PLANE: return "plane";
    case QV_COLLIDER_SPHERE: return "sphere";
    case QV_COLLIDER_BOX: return "box";
    case QV_COLLIDER_CAPSULE: return "capsule";
    case QV_COLLIDER_MESH: return "mesh";
  }
  return "unknown";
}

// Python's repr of a few numbers, for __repr__.
std::string numbers(const double* values, int count) {
  py::tuple t(count);
  for (int i = 0; i < count; ++i) t[i] = values[i];
  return py::repr(t);
}

std::shared_ptr<TriangleMesh> makeTriangleMesh(py::handle positions, py::handle triangles) {
  const Doubles p = doubles(positions, "positions", {-1, 3});
  const py::array t = py::array::ensure(triangles);
  if (!t || t.ndim() != 2 || t.shape(1) != 3) throw py::value_error("triangles must have shape (any, 3)");
  const char kind = t.dtype().kind();
  if (t.size() && kind != 'i' && kind != 'u')
    throw py::type_error("triangles must be integers, got dtype " + dtypeName(t.dtype()));
  const auto wide = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(t);
  std::vector<int> indices(static_cast<size_t>(wide.size()));
  for (size_t i = 0; i < indices.size(); ++i) {
    const long long index = wide.data()[i];
    if (index < 0 || index >= p.shape(0))
      throw py::index_error("triangle " + std::to_string(i / 3) + " names vertex " + std::to_string(index) + " of " +
                            std::to_string(p.shape(0)));
    indices[i] = static_cast<int>(index);
  }
  const py::ssize_t limit = std::numeric_limits<int>::max();
  if (p.shape(0) > limit || t.shape(0) > limit) throw py::value_error("triangle mesh too large");
  const int vertexCount = static_cast<int>(p.shape(0)), triangleCount = static_cast<int>(t.shape(0));
  qv_triangle_mesh* mesh = nullptr;
  char message[1024] = "";
  qv_result result;
  {
    py::gil_scoped_release release;  // builds a bounding volume hierarchy
    result = qv_triangle_mesh_create(p.data(), vertexCount, indices.data(), triangleCount, nullptr, &mesh, message, sizeof message);
  }
  if (result == QV_ERROR_OUT_OF_MEMORY) throw std::bad_alloc();
  if (result == QV_ERROR_FORMAT) throw FormatError(message);
  if (result != QV_OK) throw py::value_error(std::string("triangle mesh: ") + qv_result_string(result));
  return std::make_shared<TriangleMesh>(mesh, vertexCount, triangleCount);
}

} // namespace

ColliderSet ColliderSet::from(py::handle colliders) {
  ColliderSet set;
  if (colliders.is_none()) return set;
  size_t index = 0;
  for (py::handle item : py::iter(colliders)) {
    if (!py::isinstance<Collider>(item))
      throw py::type_error("colliders[" + std::to_string(index) + "] must be a quiver collider (Plane, Sphere, Box, Capsule, "
                           "MeshCollider), got " + typeName(item));
    set.owned.push_back(item.cast<const Collider&>());
    ++index;
  }
  if (set.owned.size() > static_cast<size_t>(std::numeric_limits<int>::max())) throw py::value_error("too many colliders");
  for (const Collider& c : set.owned) set.raw.push_back(c.c);
  return set;
}

void bindColliders(py::module_& m) {
  py::class_<TriangleMesh, std::shared_ptr<TriangleMesh>>(m, "TriangleMesh", R"(A closed triangle mesh for MeshCollider.

TriangleMesh(positions, triangles): positions (v, 3), triangles (t, 3) vertex indices. Checked once
(finite, no degenerate triangle, every edge shared by exactly two triangles running it in opposite
directions; an inward-facing mesh is turned outward); raises quiver.FormatError saying what and where.
Immutable; any number of colliders may share it.)")
      .def(py::init(&makeTriangleMesh), py::arg("positions"), py::arg("triangles"))
      .def_readonly("vertex_count", &TriangleMesh::vertexCount)
      .def_readonly("triangle_count", &TriangleMesh::triangleCount);

  py::class_<Collider>(m, "Collider", R"(What every collider has. Keyword arguments of each shape:
friction (Coulomb mu, default 0.5), restitution (0 no bounce .. 1 elastic, default 0), and for a
collider the game moves, velocity (m/s, of its reference point: a plane's point nearest the origin,
the centre, a capsule's first end) and angular_velocity (rad/s about that point).)")
      .def_property_readonly("type", [](const Collider& self) { return shapeName(self.c.type); })
      .def_property_readonly("friction", [](const Collider& self) { return self.c.friction; })
      .def_property_readonly("restitution", [](const Collider& self) { return self.c.restitution; })
      .def_property_readonly("velocity", [](const Collider& self) { return slice(self.c.velocity, 3); })
      .def_property_readonly("angular_velocity", [](const Collider& self) { return slice(self.c.angular_velocity, 3); })
      .def("__repr__", [](const Collider& self) {
        const int used[] = {4, 4, 6, 7, 3};
        return std::string("quiver.Collider(") + shapeName(self.c.type) + ", data=" + numbers(self.c.data, used[self.c.type]) +
               ", rotation=" + numbers(self.c.rotation, 3) + ", friction=" + std::string(py::repr(py::float_(self.c.friction))) +
               ", restitution=" + std::string(py::repr(py::float_(self.c.restitution))) + ")";
      });

  const auto zero = py::make_tuple(0.0, 0.0, 0.0);
  py::class_<Plane, Collider>(m, "Plane", "The half-space above the plane n . x = offset: the object stays on the side n points to.")
      .def(py::init([](py::handle normal, double offset, double friction, double restitution, py::handle velocity, py::handle spin) {
             auto shape = common<Plane>(QV_COLLIDER_PLANE, friction, restitution, velocity, spin);
             const std::vector<double> n = vector3(normal, "normal");
             if (n[0] == 0 && n[1] == 0 && n[2] == 0) throw py::value_error("normal must not be zero");
             if (!std::isfinite(offset)) throw py::value_error("offset must be finite");
             put(shape.c, 0, n);
             shape.c.data[3] = offset;
             return shape;
           }),
           py::arg("normal"), py::arg("offset") = 0.0, py::kw_only(), py::arg("friction") = 0.5, py::arg("restitution") = 0.0,
           py::arg("velocity") = zero, py::arg("angular_velocity") = zero)
      .def_property_readonly("normal", [](const Plane& self) { return slice(self.c.data, 3); })
      .def_property_readonly("offset", [](const Plane& self) { return self.c.data[3]; });

  py::class_<Sphere, Collider>(m, "Sphere", "A solid ball.")
      .def(py::init([](py::handle centre, double radius, double friction, double restitution, py::handle velocity, py::handle spin) {
             auto shape = common<Sphere>(QV_COLLIDER_SPHERE, friction, restitution, velocity, spin);
             checkPositive(radius, "radius");
             put(shape.c, 0, vector3(centre, "center"));
             shape.c.data[3] = radius;
             return shape;
           }),
           py::arg("center"), py::arg("radius"), py::kw_only(), py::arg("friction") = 0.5, py::arg("restitution") = 0.0,
           py::arg("velocity") = zero, py::arg("angular_velocity") = zero)
      .def_property_readonly("center", [](const Sphere& self) { return slice(self.c.data, 3); })
      .def_property_readonly("radius", [](const Sphere& self) { return self.c.data[3]; });

  py::class_<Box, Collider>(m, "Box",
                            "A solid box: centre, half extents, turned by `rotation` (axis times angle, rad) about the centre.")
      .def(py::init([](py::handle centre, py::handle halfExtents, py::handle rotation, double friction, double restitution,
                       py::handle velocity, py::handle spin) {
             auto shape = common<Box>(QV_COLLIDER_BOX, friction, restitution, velocity, spin);
             const std::vector<double> h = vector3(halfExtents, "half_extents"), turn = vector3(rotation, "rotation");
             for (double x : h) checkPositive(x, "each half extent");
             put(shape.c, 0, vector3(centre, "center"));
             put(shape.c, 3, h);
             for (int a = 0; a < 3; ++a) shape.c.rotation[a] = turn[a];
             return shape;
           }),
           py::arg("center"), py::arg("half_extents"), py::arg("rotation") = zero, py::kw_only(), py::arg("friction") = 0.5,
           py::arg("restitution") = 0.0, py::arg("velocity") = zero, py::arg("angular_velocity") = zero)
      .def_property_readonly("center", [](const Box& self) { return slice(self.c.data, 3); })
      .def_property_readonly("half_extents", [](const Box& self) { return slice(self.c.data + 3, 3); })
      .def_property_readonly("rotation", [](const Box& self) { return slice(self.c.rotation, 3); });

  py::class_<Capsule, Collider>(m, "Capsule", "The points within `radius` of the segment from `start` to `end`.")
      .def(py::init([](py::handle start, py::handle end, double radius, double friction, double restitution, py::handle velocity,
                       py::handle spin) {
             auto shape = common<Capsule>(QV_COLLIDER_CAPSULE, friction, restitution, velocity, spin);
             checkPositive(radius, "radius");
             put(shape.c, 0, vector3(start, "start"));
             put(shape.c, 3, vector3(end, "end"));
             shape.c.data[6] = radius;
             return shape;
           }),
           py::arg("start"), py::arg("end"), py::arg("radius"), py::kw_only(), py::arg("friction") = 0.5,
           py::arg("restitution") = 0.0, py::arg("velocity") = zero, py::arg("angular_velocity") = zero)
      .def_property_readonly("start", [](const Capsule& self) { return slice(self.c.data, 3); })
      .def_property_readonly("end", [](const Capsule& self) { return slice(self.c.data + 3, 3); })
      .def_property_readonly("radius", [](const Capsule& self) { return self.c.data[6]; });

  py::class_<MeshCollider, Collider>(m, "MeshCollider", R"(A TriangleMesh moved to `position` and turned by `rotation`
(axis times angle, rad) about that point. The collider keeps the mesh alive.)")
      .def(py::init([](std::shared_ptr<TriangleMesh> mesh, py::handle position, py::handle rotation, double friction,
                       double restitution, py::handle velocity, py::handle spin) {
             if (!mesh) throw py::type_error("mesh must be a quiver.TriangleMesh");
             auto shape = common<MeshCollider>(QV_COLLIDER_MESH, friction, restitution, velocity, spin);
             const std::vector<double> turn = vector3(rotation, "rotation");
             put(shape.c, 0, vector3(position, "position"));
             for (int a = 0; a < 3; ++a) shape.c.rotation[a] = turn[a];
             shape.c.mesh = mesh->get();
             shape.mesh = std::move(mesh);
             return shape;
           }),
           py::arg("mesh"), py::arg("position") = zero, py::arg("rotation") = zero, py::kw_only(), py::arg("friction") = 0.5,
           py::arg("restitution") = 0.0, py::arg("velocity") = zero, py::arg("angular_velocity") = zero)
      .def_property_readonly("mesh", [](const MeshCollider& self) { return self.mesh; })
      .def_property_readonly("position", [](const MeshCollider& self) { return slice(self.c.data, 3); })
      .def_property_readonly("rotation", [](const MeshCollider& self) { return slice(self.c.rotation, 3); });
}

} // namespace quiver_python
