// quiver._quiver: the module, its exceptions and the argument checks every binding uses. Bad
// arguments raise (TypeError, ValueError, IndexError) before they reach the C API, which takes bare
// pointers: it cannot know an array's length, and takes a NaN load as it comes.
#include <cmath>
#include <cstddef>
#include <sstream>
#include <type_traits>

#include "bindings.h"

namespace quiver_python {

std::string shapeText(const std::vector<py::ssize_t>& shape) {
  std::ostringstream text;
  text << "(";
  for (size_t i = 0; i < shape.size(); ++i) {
    if (i) text << ", ";
    if (shape[i] < 0)
      text << "any";
    else
      text << shape[i];
  }
  text << (shape.size() == 1 ? ",)" : ")");
  return text.str();
}

namespace {

std::vector<py::ssize_t> shapeOf(const py::array& a) { return std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()); }

bool shapeMatches(const py::array& a, const std::vector<py::ssize_t>& shape) {
  if (a.ndim() != static_cast<py::ssize_t>(shape.size())) return false;
  for (size_t i = 0; i < shape.size(); ++i)
    if (shape[i] >= 0 && a.shape(i) != shape[i]) return false;
  return true;
}

} // namespace

std::string typeName(py::handle value) { return py::str(py::type::handle_of(value).attr("__name__")); }

std::string dtypeName(const py::dtype& dtype) { return py::str(py::handle(dtype)); }

Doubles doubles(py::handle value, const std::string& name, const std::vector<py::ssize_t>& shape) {
  Doubles a = Doubles::ensure(value);
  if (!a) throw py::type_error(name + " must be an array of numbers, got " + typeName(value));
  if (!shapeMatches(a, shape))
    throw py::value_error(name + " must have shape " + shapeText(shape) + ", got " + shapeText(shapeOf(a)));
  const double* data = a.data();
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (!std::isfinite(data[i])) throw py::value_error(name + " contains NaN or infinity (flat index " + std::to_string(i) + ")");
  return a;
}

std::vector<double> vector3(py::handle value, const std::string& name) {
  const Doubles a = doubles(value, name, {3});
  return {a.data(), a.data() + 3};
}

void checkVertex(long long vertex, int vertexCount) {
  if (vertex < 0 || vertex >= vertexCount)
    throw py::index_error("vertex " + std::to_string(vertex) + " out of range: the model has " + std::to_string(vertexCount) +
                          " vertices");
}

std::vector<int> vertexIndices(py::handle value, const std::string& name, int vertexCount) {
  const py::array a = py::array::ensure(value);
  if (!a || a.ndim() != 1) throw py::value_error(name + " must be a one-dimensional sequence of vertex indices");
  std::vector<int> out;
  if (a.size() == 0) return out;
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u') throw py::type_error(name + " must be integers, got dtype " + dtypeName(a.dtype()));
  const auto wide = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(a);
  out.reserve(static_cast<size_t>(wide.size()));
  for (py::ssize_t i = 0; i < wide.size(); ++i) {
    checkVertex(wide.data()[i], vertexCount);
    out.push_back(static_cast<int>(wide.data()[i]));
  }
  return out;
}

py::array outputArray(py::handle out, const py::dtype& dtype, const std::vector<py::ssize_t>& shape, const std::string& name) {
  if (!py::isinstance<py::array>(out)) throw py::type_error(name + " must be a numpy array, got " + typeName(out));
  const py::array a = py::reinterpret_borrow<py::array>(out);
  if (!a.dtype().equal(dtype))
    throw py::type_error(name + " must have dtype " + dtypeName(dtype) + ", got " + dtypeName(a.dtype()));
  if (!shapeMatches(a, shape))
    throw py::value_error(name + " must have shape " + shapeText(shape) + ", got " + shapeText(shapeOf(a)));
  if (!(a.flags() & py::array::c_style)) throw py::value_error(name + " must be C-contiguous");
  if (!a.writeable()) throw py::value_error(name + " is read-only");
  return a;
}

py::object view(py::handle owner, const void* data, const py::dtype& dtype, const std::vector<py::ssize_t>& shape) {
  if (!data) return py::none();
  py::array a(dtype, shape, data, owner);
  a.attr("flags").attr("writeable") = false;
  return a;
}

py::dtype contactDtype() {
  static_assert(std::is_standard_layout<qv_contact>::value, "the dtype's offsets are qv_contact's");
  const auto i32 = py::dtype::of<int>();
  const auto vec3 = py::dtype("(3,)f8");
  py::dict spec;
  spec["names"] = py::make_tuple("vertex", "collider", "point", "normal", "impulse", "depth", "instance", "other");
  spec["formats"] = py::make_tuple(i32, i32, vec3, vec3, vec3, py::dtype::of<double>(), i32, i32);
  spec["offsets"] = py::make_tuple(offsetof(qv_contact, vertex), offsetof(qv_contact, collider), offsetof(qv_contact, point),
                                   offsetof(qv_contact, normal), offsetof(qv_contact, impulse), offsetof(qv_contact, depth),
                                   offsetof(qv_contact, instance), offsetof(qv_contact, other));
  spec["itemsize"] = sizeof(qv_contact);
  return py::dtype::from_args(spec);
}

} // namespace quiver_python

namespace {

// {name: description} of one of the C API's choices, in enum order.
template <class Enum>
pybind11::dict choices(int count, const char* (*name)(Enum), const char* (*description)(Enum)) {
  pybind11::dict out;
  for (int i = 0; i < count; ++i) out[name(static_cast<Enum>(i))] = description(static_cast<Enum>(i));
  return out;
}

} // namespace

PYBIND11_MODULE(_quiver, m) {
  namespace py = pybind11;
  using namespace quiver_python;
  if (!QV_CHECK_VERSION()) throw py::import_error("quiver: the module was compiled against other runtime headers");
  m.doc() = "Bindings of the Quiver runtime's C API (quiver/quiver.h); import `quiver`, not this module.";
  m.attr("__version__") = qv_version_string();
  m.attr("STANDARD_GRAVITY") = QV_STANDARD_GRAVITY;
  m.attr("INTEGRATORS") = choices<qv_integrator>(QV_INTEGRATOR_COUNT, qv_integrator_name, qv_integrator_description);
  m.attr("SOLVERS") = choices<qv_solver>(QV_SOLVER_COUNT, qv_solver_name, qv_solver_description);
  m.attr("ELASTICITIES") = choices<qv_elasticity>(QV_ELASTICITY_COUNT, qv_elasticity_name, qv_elasticity_description);
  m.attr("CONTACT_DTYPE") = contactDtype();

  py::register_exception<FormatError>(m, "FormatError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });

  py::enum_<qv_step_status>(m, "StepStatus", "What a step did (qv_step_status).")
      .value("OK", QV_STEP_OK)
      .value("INDEFINITE", QV_STEP_INDEFINITE, "the minimiser shifted a system matrix made indefinite by compression")
      .value("RESET", QV_STEP_RESET,
             "the state became non-finite (or central differences ran past max_displacement): reset to rest");

  bindModel(m);
  bindColliders(m);
  bindInstance(m);
}
