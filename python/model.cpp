// quiver.Model and quiver.ModelInfo: a loaded .qvr model, its summary, its stored arrays as
// read-only NumPy views (no copy; each view keeps the model alive) and the reduced elastic model.
#include <string>
#include <vector>

#include "bindings.h"

namespace quiver_python {

namespace {

// qv_model_info's fields, in order: ModelInfo's attributes and as_dict()'s keys.
const char* const kInfoFields[] = {"r", "vertex_count", "tet_count", "triangle_count", "file_vertex_count", "eigenvalue_count",
                                   "basis_precision", "material_is_uniform", "has_modal_rotations", "has_rigid_body",
                                   "youngs_modulus", "poisson_ratio", "density", "total_mass", "rayleigh_alpha",
                                   "rayleigh_beta", "time_step", "bbox_min", "bbox_max", "render_vertex_count",
                                   "render_triangle_count"};

qv_model_config modelConfig(int coefficientPrecision, int groupLayout) {
  if (coefficientPrecision != 32 && coefficientPrecision != 64)
    throw py::value_error("coefficient_precision must be 32 or 64, got " + std::to_string(coefficientPrecision));
  if (groupLayout < -1 || groupLayout > 1)
    throw py::value_error("group_layout must be -1, 0 or 1, got " + std::to_string(groupLayout));
  qv_model_config config;
  qv_model_config_init(&config);
  config.coefficient_precision = coefficientPrecision;
  config.group_layout = groupLayout;
  return config;
}

std::shared_ptr<Model> loaded(qv_result result, qv_model* model, const char* message) {
  switch (result) {
    case QV_OK: return std::make_shared<Model>(model);
    case QV_ERROR_IO: throw IoError(message);
    case QV_ERROR_FORMAT: throw FormatError(message);
    case QV_ERROR_OUT_OF_MEMORY: throw std::bad_alloc();
    default: throw py::value_error(std::string(qv_result_string(result)) + (*message ? ": " : "") + message);
  }
}

std::shared_ptr<Model> loadFile(const py::object& path, int coefficientPrecision, int groupLayout) {
  const qv_model_config config = modelConfig(coefficientPrecision, groupLayout);
  const std::string name = py::bytes(py::module_::import("os").attr("fsencode")(path));
  qv_model* model = nullptr;
  char message[1024] = "";
  qv_result result;
  {
    py::gil_scoped_release release;
    result = qv_model_load_file(name.c_str(), &config, nullptr, &model, message, sizeof message);
  }
  return loaded(result, model, message);
}

std::shared_ptr<Model> loadBytes(const py::object& data, int coefficientPrecision, int groupLayout) {
  const qv_model_config config = modelConfig(coefficientPrecision, groupLayout);
  struct Buffer {  // the bytes-like object's memory, held while it is read
    Py_buffer view{};
    explicit Buffer(PyObject* object) {
      if (PyObject_GetBuffer(object, &view, PyBUF_C_CONTIGUOUS) != 0) throw py::error_already_set();
    }
    ~Buffer() { PyBuffer_Release(&view); }
  } buffer(data.ptr());
  qv_model* model = nullptr;
  char message[1024] = "";
  qv_result result;
  {
    py::gil_scoped_release release;
    result = qv_model_load_memory(buffer.view.buf, static_cast<size_t>(buffer.view.len), &config, nullptr, &model, message,
                                  sizeof message);
  }
  return loaded(result, model, message);
}

const Model& modelOf(py::handle self) { return self.cast<const Model&>(); }

py::tuple triple(const double (&v)[3]) { return py::make_tuple(v[0], v[1], v[2]); }

using Info = const qv_model_info&;
using Shape = std::vector<py::ssize_t>;

// A property viewing one of the model's stored arrays (no copy; the view keeps the model alive),
// its shape from the model's info.
template <class T, class ShapeOf>
py::cpp_function storedArray(const T* (*getter)(const qv_model*), ShapeOf shapeOf) {
  return py::cpp_function([getter, shapeOf](py::object self) {
    const Model& model = modelOf(self);
    return view(self, getter(model.get()), py::dtype::of<T>(), shapeOf(model.info()));
  });
}

} // namespace

void bindModel(py::module_& m) {
  py::class_<qv_model_info>(m, "ModelInfo", "A model's summary (qv_model_info): sizes, material, default damping and step, "
                                            "bounding box. Read-only; as_dict() gives every field.")
      .def_readonly("r", &qv_model_info::r, "reduced coordinates q")
      .def_readonly("vertex_count", &qv_model_info::vertex_count, "simulated vertices")
      .def_readonly("tet_count", &qv_model_info::tet_count)
      .def_readonly("triangle_count", &qv_model_info::triangle_count, "surface triangles")
      .def_readonly("file_vertex_count", &qv_model_info::file_vertex_count, "vertices of the mesh file it was baked from")
      .def_readonly("eigenvalue_count", &qv_model_info::eigenvalue_count)
      .def_readonly("basis_precision", &qv_model_info::basis_precision, "32 or 64 bits per stored basis entry")
      .def_property_readonly("material_is_uniform", [](const qv_model_info& i) { return i.material_is_uniform != 0; })
      .def_property_readonly("has_modal_rotations", [](const qv_model_info& i) { return i.has_modal_rotations != 0; },
                             "the model can be simulated with elasticity='warping'")
      .def_property_readonly("has_rigid_body", [](const qv_model_info& i) { return i.has_rigid_body != 0; },
                             "baked free: instances can fly (free_flight=True)")
      .def_readonly("youngs_modulus", &qv_model_info::youngs_modulus, "Pa (volume-weighted mean when mixed)")
      .def_readonly("poisson_ratio", &qv_model_info::poisson_ratio)
      .def_readonly("density", &qv_model_info::density, "kg/m^3")
      .def_readonly("total_mass", &qv_model_info::total_mass, "kg")
      .def_readonly("rayleigh_alpha", &qv_model_info::rayleigh_alpha, "default damping alpha, 1/s")
      .def_readonly("rayleigh_beta", &qv_model_info::rayleigh_beta, "default damping beta, s")
      .def_readonly("time_step", &qv_model_info::time_step, "suggested time step, s")
      .def_property_readonly("bbox_min", [](const qv_model_info& i) { return triple(i.bbox_min); })
      .def_property_readonly("bbox_max", [](const qv_model_info& i) { return triple(i.bbox_max); })
      .def_readonly("render_vertex_count", &qv_model_info::render_vertex_count, "0 when the model has no render mesh")
      .def_readonly("render_triangle_count", &qv_model_info::render_triangle_count)
      .def("as_dict", [](py::object self) {
        py::dict out;
        for (const char* field : kInfoFields) out[field] = self.attr(field);
        return out;
      })
      .def("__repr__", [](const qv_model_info& i) {
        return "ModelInfo(r=" + std::to_string(i.r) + ", vertex_count=" + std::to_string(i.vertex_count) +
               ", tet_count=" + std::to_string(i.tet_count) + ", total_mass=" + std::string(py::repr(py::float_(i.total_mass))) +
               ", has_rigid_body=" + (i.has_rigid_body ? "True" : "False") + ")";
      });

  py::class_<Model, std::shared_ptr<Model>>(m, "Model", R"(A baked model (.qvr), immutable; share it between any number of Instances.

Model(path, coefficient_precision=64, group_layout=-1) loads a file; Model.from_bytes(data) an image
in memory. coefficient_precision=32 keeps the packed quartic in float32 (at r = 30: 0.97 MB instead
of 1.43 without the groups' layout, 1.62 instead of 2.67 with it), force and stiffness within about
1e-7 relative. group_layout: 1 lays the coefficients out a second time for step_many's groups of 16
(crowds 2.8x faster than one by one at r = 30 on a Zen 5; 2.67 MB instead of 1.43 at r = 30 in
float64), 0 does not (step_many then steps this model's instances one by one), -1 (default) does up
to r = 64.
Raises OSError (unreadable file) or quiver.FormatError (not a valid model: the message names the
file, the section, the offset and what is wrong).

The stored arrays are read-only views of the model's memory (no copy); each keeps the model alive.)")
      .def(py::init(&loadFile), py::arg("path"), py::arg("coefficient_precision") = 64, py::arg("group_layout") = -1)
      .def_static("from_bytes", &loadBytes, py::arg("data"), py::arg("coefficient_precision") = 64,
                  py::arg("group_layout") = -1,
                  "Loads a .qvr image from any bytes-like object (copied: the object may change afterwards).")
      .def_property_readonly("info", [](const Model& self) { return self.info(); }, "the model's ModelInfo")
      .def_property_readonly("rest_positions",
                             storedArray(qv_model_rest_positions, [](Info i) { return Shape{i.vertex_count, 3}; }),
                             "(n, 3) float64: each vertex's rest position")
      .def_property_readonly("triangles",
                             storedArray(qv_model_triangles, [](Info i) { return Shape{i.triangle_count, 3}; }),
                             "(t, 3) uint32: the surface triangles' vertex indices")
      .def_property_readonly("vertex_map",
                             storedArray(qv_model_vertex_map, [](Info i) { return Shape{i.vertex_count}; }),
                             "(n,) uint32: each vertex's 0-based index in the mesh file it was baked from")
      .def_property_readonly("eigenvalues",
                             storedArray(qv_model_eigenvalues, [](Info i) { return Shape{i.eigenvalue_count}; }),
                             "(e,) float64: the baked modes' eigenvalues, (rad/s)^2 in SI units")
      .def_property_readonly("gravity", storedArray(qv_model_gravity, [](Info i) { return Shape{3, i.r}; }),
                             "(3, r) float64: row a is U^T M e_a, the reduced force of a unit acceleration along axis a")
      .def_property_readonly("render_rest_positions",
                             storedArray(qv_model_render_rest_positions, [](Info i) { return Shape{i.render_vertex_count, 3}; }),
                             "(V, 3) float32, or None without a render mesh")
      .def_property_readonly("render_triangles",
                             storedArray(qv_model_render_triangles, [](Info i) { return Shape{i.render_triangle_count, 3}; }),
                             "(T, 3) uint32, counter-clockwise seen from outside, or None")
      .def_property_readonly("render_normals",
                             storedArray(qv_model_render_normals, [](Info i) { return Shape{i.render_vertex_count, 3}; }),
                             "(V, 3) float32 rest normals, or None")
      .def_property_readonly("render_uvs",
                             storedArray(qv_model_render_uvs, [](Info i) { return Shape{i.render_vertex_count, 2}; }),
                             "(V, 2) float32, or None when the render mesh has no UVs")
      .def("evaluate", [](const Model& self, py::handle q) {
        const int r = self.info().r;
        const Doubles at = doubles(q, "q", {r});
        py::array_t<double> force(r), stiffness({r, r});
        std::vector<double> scratch(qv_model_scratch_size(self.get()) / sizeof(double) + 1);
        double energy = 0;
        qv_model_evaluate(self.get(), at.data(), &energy, force.mutable_data(), stiffness.mutable_data(), scratch.data());
        return py::make_tuple(energy, force, stiffness);
      }, py::arg("q"), R"(The reduced elastic model at q (r values): (energy E(q) in J, internal force R(q) = dE/dq
(r,), stiffness K(q) = dR/dq (r, r), symmetric).)")
      .def("displacements", [](const Model& self, py::handle q) {
        const Doubles at = doubles(q, "q", {self.info().r});
        py::array_t<float> out({self.info().vertex_count, 3});
        qv_model_displacements(self.get(), at.data(), out.mutable_data());
        return out;
      }, py::arg("q"), "Each vertex's displacement u = U q: (n, 3) float32.")
      .def("surface_normals", [](const Model& self, py::handle positions) {
        const int n = self.info().vertex_count;
        const Doubles at = doubles(positions, "positions", {n, 3});
        const std::vector<float> p(at.data(), at.data() + 3 * static_cast<size_t>(n));
        py::array_t<float> out({n, 3});
        qv_model_surface_normals(self.get(), p.data(), out.mutable_data());
        return out;
      }, py::arg("positions"), "Area-weighted normals of the surface at these vertex positions (n, 3); 0 off the surface.")
      .def("__repr__", [](const Model& self) {
        const qv_model_info& i = self.info();
        return "quiver.Model(r=" + std::to_string(i.r) + ", vertices=" + std::to_string(i.vertex_count) +
               ", tets=" + std::to_string(i.tet_count) + (i.has_rigid_body ? ", free" : "") + ")";
      });
}

} // namespace quiver_python
