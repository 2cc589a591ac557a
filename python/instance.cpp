// quiver.Instance (one simulated object), quiver.RigidState, quiver.World and quiver.step_many.
// Steps run with the GIL released; meanwhile the instances they step are marked busy, and any other
// call on them (from another Python thread) raises instead of racing the step.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <unordered_set>

#include <pybind11/stl.h>

#include "bindings.h"

namespace quiver_python {

Instance::Instance(std::shared_ptr<Model> owner, const qv_instance_config& settings) : model(std::move(owner)), config(settings) {
  const qv_result result = qv_instance_create(model->get(), &config, nullptr, &instance_);
  if (result == QV_ERROR_OUT_OF_MEMORY) throw std::bad_alloc();
  if (result != QV_OK) throw py::value_error("invalid instance configuration (qv_instance_create refused it)");
}

qv_instance* Instance::use() {
  if (busy) throw std::runtime_error("this instance is being stepped on another thread (Instance.step, step_many or World.step)");
  return instance_;
}

BusyGuard::BusyGuard(std::vector<Instance*> instances) : instances_(std::move(instances)) {
  for (Instance* s : instances_) s->use();
  for (Instance* s : instances_) s->busy = true;
}

BusyGuard::~BusyGuard() {
  for (Instance* s : instances_) s->busy = false;
}

qv_world* World::use() const {
  if (busy) throw std::runtime_error("this world is being stepped on another thread (World.step)");
  return world_;
}

World::World(const qv_world_config& settings) : config(settings) {
  const qv_result result = qv_world_create(&config, nullptr, &world_);
  if (result == QV_ERROR_OUT_OF_MEMORY) throw std::bad_alloc();
  if (result != QV_OK) throw py::value_error("invalid world configuration");
}

World::~World() {
  qv_world_destroy(world_);
  for (const py::object& s : instances) s.cast<Instance&>().world = nullptr;
}

namespace {

template <class Enum>
Enum choice(const std::optional<std::string>& name, Enum fallback, qv_result (*fromName)(const char*, Enum*), const char* what,
            int count, const char* (*nameOf)(Enum)) {
  if (!name) return fallback;
  Enum value = fallback;
  if (fromName(name->c_str(), &value) == QV_OK) return value;
  std::string known;
  for (int i = 0; i < count; ++i) known += std::string(i ? ", " : "") + "'" + nameOf(static_cast<Enum>(i)) + "'";
  throw py::value_error(std::string("unknown ") + what + " '" + *name + "': one of " + known);
}

void require(bool ok, const std::string& message) {
  if (!ok) throw py::value_error(message);
}

// What save(data) writes into `most` bytes (8-byte aligned, as the C API wants), as the bytes it used.
template <class Save>
py::bytes saveSnapshot(size_t most, Save save) {
  std::vector<double> aligned(most / sizeof(double) + 1);
  return py::bytes(reinterpret_cast<const char*>(aligned.data()), save(aligned.data()));
}

// Restores `snapshot` with restore(data, size) (8-byte aligned, as the C API wants), or raises.
template <class Restore>
void restoreSnapshot(const py::bytes& snapshot, const std::string& whose, size_t most, Restore restore) {
  const std::string bytes = snapshot;
  const std::string size = "snapshot of " + std::to_string(bytes.size()) + " bytes";
  require(bytes.size() <= most, size + "; " + whose + " take at most " + std::to_string(most));
  std::vector<double> aligned(bytes.size() / sizeof(double) + 1);
  std::memcpy(aligned.data(), bytes.data(), bytes.size());
  require(restore(aligned.data(), bytes.size()) == QV_OK,
          size + " refused: not one " + whose + " could have saved (cut short, another model's r, a world of another size, a "
          "value not finite, a damping stiffness not positive definite, or contacts no step could have ended with)");
}

// qv_instance_config_init's defaults with the keyword arguments given, each checked with a message.
qv_instance_config instanceConfig(const Model& model, const std::optional<std::string>& integrator,
                                  const std::optional<std::string>& solver, const std::optional<std::string>& elasticity,
                                  std::optional<double> timeStep, std::optional<int> newtonIterations,
                                  std::optional<double> newtonTolerance, std::optional<double> alpha, std::optional<double> beta,
                                  std::optional<int> maxConstraints, std::optional<double> maxDisplacement, bool freeFlight,
                                  std::optional<int> maxContacts, bool softContacts, std::optional<int> maxSubsteps) {
  qv_instance_config c;
  qv_instance_config_init(&c, model.get());
  c.integrator = choice(integrator, c.integrator, qv_integrator_from_name, "integrator", QV_INTEGRATOR_COUNT, qv_integrator_name);
  c.solver = choice(solver, c.solver, qv_solver_from_name, "solver", QV_SOLVER_COUNT, qv_solver_name);
  c.elasticity = choice(elasticity, c.elasticity, qv_elasticity_from_name, "elasticity", QV_ELASTICITY_COUNT, qv_elasticity_name);
  c.time_step = timeStep.value_or(c.time_step);
  c.newton_iterations = newtonIterations.value_or(c.newton_iterations);
  c.newton_tolerance = newtonTolerance.value_or(c.newton_tolerance);
  c.rayleigh_alpha = alpha.value_or(c.rayleigh_alpha);
  c.rayleigh_beta = beta.value_or(c.rayleigh_beta);
  c.max_constraints = maxConstraints.value_or(c.max_constraints);
  c.max_displacement = maxDisplacement.value_or(c.max_displacement);
  c.free_flight = freeFlight ? 1 : 0;
  c.max_contacts = maxContacts.value_or(c.max_contacts);
  c.soft_contacts = softContacts ? 1 : 0;
  c.max_substeps = maxSubsteps.value_or(c.max_substeps);
  require(c.time_step >= QV_MIN_TIME_STEP && std::isfinite(c.time_step), "time_step must be finite and at least 1e-12 s");
  require(c.newton_iterations >= 1, "newton_iterations must be at least 1");
  require(c.newton_tolerance > 0 && std::isfinite(c.newton_tolerance), "newton_tolerance must be positive and finite");
  require(c.rayleigh_alpha >= 0 && std::isfinite(c.rayleigh_alpha), "rayleigh_alpha must be >= 0 and finite");
  require(c.rayleigh_beta >= 0 && std::isfinite(c.rayleigh_beta), "rayleigh_beta must be >= 0 and finite");
  require(c.max_constraints >= 0 && c.max_constraints <= 64, "max_constraints must be between 0 and 64");
  require(c.max_displacement > 0, "max_displacement must be positive");
  require(c.max_contacts >= 0 && c.max_contacts <= 4096, "max_contacts must be between 0 and 4096");
  require(c.max_substeps >= 1 && c.max_substeps <= 64, "max_substeps must be between 1 and 64");
  require(!freeFlight || model.info().has_rigid_body, "free_flight needs a model baked free (info.has_rigid_body)");
  require(!softContacts || (freeFlight && c.integrator != QV_INTEGRATOR_CENTRAL_DIFFERENCES &&
                             c.elasticity != QV_ELASTICITY_MODAL_WARPING),
          "soft_contacts needs free_flight=True, an implicit integrator ('newmark' or 'euler') and no modal warping");
  require(c.elasticity != QV_ELASTICITY_MODAL_WARPING || model.info().has_modal_rotations,
          "elasticity 'warping' needs a model with modal rotations (info.has_modal_rotations)");
  return c;
}

py::dict configDict(const qv_instance_config& c) {
  py::dict d;
  d["integrator"] = qv_integrator_name(c.integrator);
  d["solver"] = qv_solver_name(c.solver);
  d["elasticity"] = qv_elasticity_name(c.elasticity);
  d["time_step"] = c.time_step;
  d["newton_iterations"] = c.newton_iterations;
  d["newton_tolerance"] = c.newton_tolerance;
  d["rayleigh_alpha"] = c.rayleigh_alpha;
  d["rayleigh_beta"] = c.rayleigh_beta;
  d["max_constraints"] = c.max_constraints;
  d["max_displacement"] = c.max_displacement;
  d["free_flight"] = c.free_flight != 0;
  d["max_contacts"] = c.max_contacts;
  d["soft_contacts"] = c.soft_contacts != 0;
  d["max_substeps"] = c.max_substeps;
  return d;
}

enum class Part { q, velocity, acceleration };

py::array_t<double> statePart(const Instance& self, Part part) {
  py::array_t<double> out(self.model->info().r);
  double* p = out.mutable_data();
  qv_instance_get_state(self.use(), part == Part::q ? p : nullptr, part == Part::velocity ? p : nullptr,
                        part == Part::acceleration ? p : nullptr);
  return out;
}

void setState(Instance& self, py::handle q, py::handle velocity, py::handle acceleration) {
  const py::ssize_t r = self.model->info().r;
  std::optional<Doubles> parts[3];
  const py::handle given[3] = {q, velocity, acceleration};
  const char* names[3] = {"q", "velocity", "acceleration"};
  for (int i = 0; i < 3; ++i)
    if (!given[i].is_none()) parts[i] = doubles(given[i], names[i], {r});
  const auto pointer = [](const std::optional<Doubles>& a) { return a ? a->data() : nullptr; };
  qv_instance_set_state(self.use(), pointer(parts[0]), pointer(parts[1]), pointer(parts[2]));
}

qv_rigid_state rigidState(py::handle position, py::handle orientation, py::handle velocity, py::handle spin) {
  qv_rigid_state s{};
  const std::vector<double> x = vector3(position, "position"), v = vector3(velocity, "linear_velocity"),
                            w = vector3(spin, "angular_velocity");
  const Doubles turn = doubles(orientation, "orientation", {4});
  double norm = 0;
  for (int i = 0; i < 4; ++i) norm += turn.data()[i] * turn.data()[i];
  require(norm > 0 && std::isfinite(norm), "orientation must be a non-zero quaternion (w, x, y, z)");
  std::copy(x.begin(), x.end(), s.position);
  std::copy(turn.data(), turn.data() + 4, s.orientation);
  std::copy(v.begin(), v.end(), s.linear_velocity);
  std::copy(w.begin(), w.end(), s.angular_velocity);
  return s;
}

template <size_t N>
py::array_t<double> copyOf(const double (&values)[N]) {
  py::array_t<double> out(static_cast<py::ssize_t>(N));
  std::copy(values, values + N, out.mutable_data());
  return out;
}

template <size_t N>
void assign(double (&to)[N], py::handle value, const char* name) {
  const Doubles a = doubles(value, name, {static_cast<py::ssize_t>(N)});
  std::copy(a.data(), a.data() + N, to);
}

// The contacts a C call copies out, as a structured array of CONTACT_DTYPE.
template <class Source>
py::array contactArray(const Source* source, int (*copy)(const Source*, qv_contact*, int)) {
  const int count = copy(source, nullptr, 0);
  py::array out(contactDtype(), std::vector<py::ssize_t>{count});
  copy(source, static_cast<qv_contact*>(out.mutable_data()), count);
  return out;
}

qv_step_status worse(qv_step_status a, qv_step_status b) { return std::max(a, b); }

// qv_job_runner on std::thread: job 0 on the calling thread, the others on threads of their own,
// or here too where the system gives no thread (the runtime must not see an exception).
void runOnThreads(void*, qv_job_function job, void* data, int count) {
  std::vector<std::thread> threads;
  int next = 1;
  try {
    threads.reserve(static_cast<size_t>(count));
    for (; next < count; ++next) threads.emplace_back(job, data, next);
  } catch (const std::exception&) {
  }
  for (int i = next; i < count; ++i) job(data, i);
  job(data, 0);
  for (std::thread& t : threads) t.join();
}

py::list stepMany(py::handle sequence, int threads) {
  if (threads < 1) throw py::value_error("threads must be at least 1");
  std::vector<py::object> held;  // alive even if the caller's list changes while the GIL is released
  std::vector<Instance*> instances;
  for (py::handle item : py::iter(sequence)) {
    if (!py::isinstance<Instance>(item))
      throw py::type_error("step_many takes quiver.Instance objects; item " + std::to_string(held.size()) + " is a " +
                           typeName(item));
    held.push_back(py::reinterpret_borrow<py::object>(item));
    instances.push_back(&item.cast<Instance&>());
  }
  py::list out;
  if (instances.empty()) return out;
  if (instances.size() > static_cast<size_t>(std::numeric_limits<int>::max())) throw py::value_error("too many instances");
  std::unordered_set<const Instance*> seen;
  for (size_t i = 0; i < instances.size(); ++i) {
    const Instance* s = instances[i];
    if (s->model != instances[0]->model)
      throw py::value_error("step_many: every instance must be of the same Model object (item " + std::to_string(i) +
                            " is of another)");
    if (!seen.insert(s).second) throw py::value_error("step_many: item " + std::to_string(i) + " appears twice");
    if (s->world) throw py::value_error("step_many: item " + std::to_string(i) + " is in a World, which steps it");
  }
  const int count = static_cast<int>(instances.size());
  // Jobs are cut on whole groups: more jobs than groups would only idle (and change no bit).
  const int jobCount = std::min(threads, (count + QV_GROUP_SIZE - 1) / QV_GROUP_SIZE);
  const qv_model* model = instances[0]->model->get();
  const size_t bytes = qv_instances_step_scratch_size(model, jobCount);
  const AlignedBuffer scratch(bytes);
  std::vector<qv_instance*> handles;
  for (Instance* s : instances) handles.push_back(s->raw());
  std::vector<qv_step_status> statuses(instances.size());
  const qv_job_runner runner{jobCount, runOnThreads, nullptr};
  qv_result result;
  {
    BusyGuard guard(instances);
    py::gil_scoped_release release;
    result = qv_instances_step(handles.data(), count, jobCount > 1 ? &runner : nullptr, scratch.get(), bytes, statuses.data());
  }
  if (result != QV_OK) throw py::value_error(std::string("qv_instances_step: ") + qv_result_string(result));
  for (qv_step_status s : statuses) out.append(s);
  return out;
}

} // namespace

void bindInstance(py::module_& m) {
  const auto zero = py::make_tuple(0.0, 0.0, 0.0);
  py::class_<qv_rigid_state>(m, "RigidState", R"(The frame of a flying instance (qv_rigid_state): its centre of mass's
position (m), orientation (unit quaternion w, x, y, z; normalised when set), linear_velocity (m/s) and
angular_velocity (rad/s, world axes). Each attribute reads as a new array and takes any 3 (or 4) numbers.)")
      .def(py::init(&rigidState), py::arg("position") = zero, py::arg("orientation") = py::make_tuple(1.0, 0.0, 0.0, 0.0),
           py::arg("linear_velocity") = zero, py::arg("angular_velocity") = zero)
      .def_property("position", [](const qv_rigid_state& s) { return copyOf(s.position); },
                    [](qv_rigid_state& s, py::handle v) { assign(s.position, v, "position"); })
      .def_property("orientation", [](const qv_rigid_state& s) { return copyOf(s.orientation); },
                    [](qv_rigid_state& s, py::handle v) {
                      s = rigidState(copyOf(s.position), v, copyOf(s.linear_velocity), copyOf(s.angular_velocity));
                    })
      .def_property("linear_velocity", [](const qv_rigid_state& s) { return copyOf(s.linear_velocity); },
                    [](qv_rigid_state& s, py::handle v) { assign(s.linear_velocity, v, "linear_velocity"); })
      .def_property("angular_velocity", [](const qv_rigid_state& s) { return copyOf(s.angular_velocity); },
                    [](qv_rigid_state& s, py::handle v) { assign(s.angular_velocity, v, "angular_velocity"); })
      .def("__repr__", [](py::object self) {
        return "quiver.RigidState(position=" + std::string(py::repr(self.attr("position").attr("tolist")())) +
               ", orientation=" + std::string(py::repr(self.attr("orientation").attr("tolist")())) + ")";
      });

  py::class_<Instance>(m, "Instance", R"(One simulated object of a Model: M q'' + C q' + R(q) = f in the model's r reduced
coordinates, C = alpha I + beta K (Rayleigh). Keeps its model alive.

Instance(model, *, integrator, solver, elasticity, time_step, newton_iterations, newton_tolerance,
rayleigh_alpha, rayleigh_beta, max_constraints, max_displacement, free_flight, max_contacts, soft_contacts,
max_substeps):
each keyword is a field of qv_instance_config; left out (None), it takes qv_instance_config_init's
default: integrator 'newmark' (or 'euler', 'central'; see quiver.INTEGRATORS), solver 'minimize'
(or 'newton'), elasticity 'stvk' (or 'linear', 'warping'), the model's time step and damping,
newton_iterations 8, newton_tolerance 1e-6, max_constraints 4, max_displacement 100 x the model's
diagonal, free_flight False (True: it flies in a moving frame; needs info.has_rigid_body),
max_contacts 64, soft_contacts False (True, flying and stepped implicitly: contacts hold the
deformed surface, which gives way where they push, so a soft object rests flat on what holds it),
max_substeps 16 (flying, q's step is cut so that the body turns at most 0.75 rad in each, at most
this many; 1 never cuts).

Vertex forces and the reduced force are per step (cleared by each step); gravity, constraints and
colliders persist. Positions and normals are in the world (in flight, carried by the frame).)")
      .def(py::init([](std::shared_ptr<Model> model, const std::optional<std::string>& integrator,
                       const std::optional<std::string>& solver, const std::optional<std::string>& elasticity,
                       std::optional<double> timeStep, std::optional<int> newtonIterations, std::optional<double> newtonTolerance,
                       std::optional<double> alpha, std::optional<double> beta, std::optional<int> maxConstraints,
                       std::optional<double> maxDisplacement, bool freeFlight, std::optional<int> maxContacts,
                       bool softContacts, std::optional<int> maxSubsteps) {
             if (!model) throw py::type_error("model must be a quiver.Model");
             const qv_instance_config config = instanceConfig(*model, integrator, solver, elasticity, timeStep, newtonIterations,
                                                              newtonTolerance, alpha, beta, maxConstraints, maxDisplacement,
                                                              freeFlight, maxContacts, softContacts, maxSubsteps);
             return std::make_unique<Instance>(std::move(model), config);
           }),
           py::arg("model"), py::kw_only(), py::arg("integrator") = py::none(), py::arg("solver") = py::none(),
           py::arg("elasticity") = py::none(), py::arg("time_step") = py::none(), py::arg("newton_iterations") = py::none(),
           py::arg("newton_tolerance") = py::none(), py::arg("rayleigh_alpha") = py::none(), py::arg("rayleigh_beta") = py::none(),
           py::arg("max_constraints") = py::none(), py::arg("max_displacement") = py::none(), py::arg("free_flight") = false,
           py::arg("max_contacts") = py::none(), py::arg("soft_contacts") = false, py::arg("max_substeps") = py::none())
      .def_property_readonly("model", [](const Instance& self) { return self.model; })
      .def_property_readonly("config", [](const Instance& self) { return configDict(self.config); },
                             "the qv_instance_config it was made with, as a dict (choices by name)")
      .def_property_readonly("flying", [](const Instance& self) { return self.config.free_flight != 0; })
      .def_property_readonly("time_step", [](const Instance& self) { return self.config.time_step; })
      .def_property_readonly("stable_time_step", [](const Instance& self) { return qv_instance_stable_time_step(self.use()); },
                             "largest stable step of central differences at rest under its Rayleigh damping, s")
      .def("step", [](Instance& self, long long count) {
             if (count < 0) throw py::value_error("count must be >= 0");
             if (self.world) throw py::value_error("this instance is in a World, which steps it (World.step)");
             qv_step_status status = QV_STEP_OK;
             BusyGuard guard({&self});
             py::gil_scoped_release release;
             for (long long i = 0; i < count; ++i) status = worse(status, qv_instance_step(self.raw()));
             return status;
           },
           py::arg("count") = 1, R"(Advances `count` time steps (each under the loads set so far; per-step loads are
cleared after the first). Returns a StepStatus: OK, INDEFINITE (the minimiser shifted an indefinite system)
or RESET (the state became non-finite, or central differences ran past max_displacement, and was reset to
rest), the worst of the steps taken; last_step describes the last.)")
      .def_property_readonly("last_step", [](const Instance& self) {
        qv_step_report r;
        qv_instance_last_step(self.use(), &r);
        py::dict d;
        d["newton_iterations"] = r.newton_iterations;
        d["line_search_cuts"] = r.line_search_cuts;
        d["converged"] = r.converged != 0;
        d["gradient"] = r.gradient;
        d["held_back"] = r.held_back != 0;
        d["energy_removed"] = r.energy_removed;
        d["minimized"] = r.minimized != 0;
        d["substeps"] = r.substeps;
        return d;
      }, "what the last step did (qv_step_report), as a dict")
      .def_property("q", [](const Instance& self) { return statePart(self, Part::q); },
                    [](Instance& self, py::handle q) { setState(self, q, py::none(), py::none()); },
                    "reduced coordinates (r,), a copy; setting it recomputes the acceleration")
      .def_property("velocity", [](const Instance& self) { return statePart(self, Part::velocity); },
                    [](Instance& self, py::handle v) { setState(self, py::none(), v, py::none()); })
      .def_property_readonly("acceleration", [](const Instance& self) { return statePart(self, Part::acceleration); })
      .def("set_state", &setState, py::arg("q") = py::none(), py::arg("velocity") = py::none(), py::arg("acceleration") = py::none(),
           "Sets any of q, velocity, acceleration; without an acceleration, the one the equations of motion give there.")
      .def("reset", [](Instance& self) { qv_instance_reset(self.use()); }, "Back to rest (in flight: to the last rigid state set).")
      .def_property_readonly("asleep", [](const Instance& self) { return qv_instance_asleep(self.use()) != 0; },
                             "Asleep in its World: not stepped until something wakes it.")
      .def("wake", [](Instance& self) { qv_instance_wake(self.use()); }, "Wakes it (and the group it sleeps with) in its World.")
      .def("energies", [](const Instance& self) {
        double kinetic = 0, elastic = 0;
        qv_instance_energies(self.use(), &kinetic, &elastic);
        return py::make_tuple(kinetic, elastic);
      }, "(kinetic, elastic) energy in J")
      .def("save_snapshot", [](const Instance& self) {
        return saveSnapshot(qv_instance_snapshot_size(self.use()), [&](void* data) { return qv_instance_save_snapshot(self.use(), data); });
      }, "Everything that evolves (in flight its contacts too), as bytes: restoring them and repeating the same calls "
         "repeats the same bits.")
      .def("restore_snapshot", [](Instance& self, const py::bytes& snapshot) {
        restoreSnapshot(snapshot, "this instance's", qv_instance_snapshot_size(self.use()), [&](const void* data, size_t size) {
          return qv_instance_restore_snapshot(self.use(), data, size);
        });
      }, py::arg("snapshot"))
      .def("add_vertex_force", [](Instance& self, long long vertex, py::handle force) {
        checkVertex(vertex, self.model->info().vertex_count);
        const std::vector<double> f = vector3(force, "force");
        qv_instance_add_vertex_force(self.use(), static_cast<int>(vertex), f.data());
      }, py::arg("vertex"), py::arg("force"), "A force (N, world) on one vertex for the next step.")
      .def("add_reduced_force", [](Instance& self, py::handle force) {
        const Doubles f = doubles(force, "force", {self.model->info().r});
        qv_instance_add_reduced_force(self.use(), f.data());
      }, py::arg("force"), "A reduced force (r,) for the next step.")
      .def("set_gravity", [](Instance& self, py::handle acceleration) {
        const std::vector<double> g = vector3(acceleration, "acceleration");
        qv_instance_set_gravity(self.use(), g.data());
      }, py::arg("acceleration"), "Persistent gravity, m/s^2 (world axes), e.g. (0, 0, -quiver.STANDARD_GRAVITY).")
      .def("set_constraint", [](Instance& self, int slot, py::handle vertices, py::handle targets, double stiffness) {
        if (self.config.free_flight) throw py::value_error("penalty constraints are for pinned models, not flying instances");
        if (slot < 0 || slot >= self.config.max_constraints)
          throw py::index_error("constraint slot " + std::to_string(slot) + " out of range: this instance has max_constraints=" +
                                std::to_string(self.config.max_constraints));
        const std::vector<int> v = vertexIndices(vertices, "vertices", self.model->info().vertex_count);
        if (v.empty()) throw py::value_error("vertices must not be empty");
        const Doubles t = doubles(targets, "targets", {static_cast<py::ssize_t>(v.size()), 3});
        if (!(stiffness > 0) || !std::isfinite(stiffness)) throw py::value_error("stiffness must be positive and finite");
        if (qv_instance_set_constraint(self.use(), slot, v.data(), static_cast<int>(v.size()), t.data(), stiffness) != QV_OK)
          throw py::value_error("qv_instance_set_constraint refused the constraint");
      }, py::arg("slot"), py::arg("vertices"), py::arg("targets"), py::arg("stiffness"),
         R"(Pulls `vertices` (k,) toward `targets` (k, 3) with a spring of `stiffness` N/m per vertex, in slot
0..max_constraints-1, until cleared or replaced: a dragged vertex, or a group a caller moves.)")
      .def("clear_constraint", [](Instance& self, int slot) {
        if (slot < 0 || slot >= self.config.max_constraints)
          throw py::index_error("constraint slot " + std::to_string(slot) + " out of range: this instance has max_constraints=" +
                                std::to_string(self.config.max_constraints));
        qv_instance_clear_constraint(self.use(), slot);
      }, py::arg("slot"))
      .def_property("rigid_state", [](const Instance& self) {
        qv_rigid_state s;
        if (qv_instance_get_rigid_state(self.use(), &s) != QV_OK) throw py::value_error("only a flying instance has a rigid state");
        return s;
      }, [](Instance& self, const qv_rigid_state& s) {
        if (!self.config.free_flight) throw py::value_error("only a flying instance has a rigid state");
        if (qv_instance_set_rigid_state(self.use(), &s) != QV_OK) throw py::value_error("invalid rigid state");
      }, "the frame of a flying instance (RigidState, a copy); setting it also sets where a reset returns to")
      .def("set_colliders", [](Instance& self, py::handle colliders) {
        if (!self.config.free_flight) throw py::value_error("colliders are for flying instances (free_flight=True)");
        ColliderSet set = ColliderSet::from(colliders);
        if (qv_instance_set_colliders(self.use(), set.raw.data(), static_cast<int>(set.raw.size())) != QV_OK)
          throw py::value_error("qv_instance_set_colliders refused the colliders");
        self.colliders = std::move(set);  // after the call: on a refusal the C API keeps the old array
      }, py::arg("colliders"), "The colliders a flying instance meets (a list; copied: to move one, pass a new list).")
      .def("contacts", [](const Instance& self) { return contactArray(self.use(), qv_instance_contacts); },
           "The last step's contacts as a structured array of quiver.CONTACT_DTYPE (vertex, collider, point, normal, "
           "impulse (N s), depth, instance, other).")
      .def("positions", [](const Instance& self, py::handle out) {
        const int n = self.model->info().vertex_count;
        py::array target =
            out.is_none() ? py::array(py::array_t<float>({n, 3})) : outputArray(out, py::dtype::of<float>(), {n, 3}, "out");
        qv_instance_positions(self.use(), static_cast<float*>(target.mutable_data()));
        return target;
      }, py::arg("out") = py::none(), "Deformed positions (n, 3) float32: a new array, or written into `out` (no allocation).")
      .def("positions_of", [](const Instance& self, py::handle vertices) {
        const std::vector<int> v = vertexIndices(vertices, "vertices", self.model->info().vertex_count);
        py::array_t<float> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
        if (!v.empty() && qv_instance_positions_of(self.use(), v.data(), static_cast<int>(v.size()), out.mutable_data()) != QV_OK)
          throw py::value_error("qv_instance_positions_of refused the vertices");
        return out;
      }, py::arg("vertices"), "Deformed positions (k, 3) float32 of the listed vertices.")
      .def("render", [](Instance& self, py::handle out) {
        const int n = self.model->info().render_vertex_count;
        if (n == 0) throw py::value_error("the model has no render mesh (baked without --render-mesh)");
        py::array positions, normals;
        if (out.is_none()) {
          positions = py::array_t<float>({n, 3});
          normals = py::array_t<float>({n, 3});
        } else {
          const py::tuple pair(py::reinterpret_borrow<py::object>(out));
          if (pair.size() != 2) throw py::value_error("out must be a pair (positions, normals)");
          positions = outputArray(pair[0], py::dtype::of<float>(), {n, 3}, "out[0]");
          normals = outputArray(pair[1], py::dtype::of<float>(), {n, 3}, "out[1]");
        }
        if (!self.renderScratch.get()) self.renderScratch = AlignedBuffer(qv_model_render_scratch_size(self.model->get()), 16);
        qv_instance_render(self.use(), static_cast<float*>(positions.mutable_data()), static_cast<float*>(normals.mutable_data()),
                           self.renderScratch.get());
        return py::make_tuple(positions, normals);
      }, py::arg("out") = py::none(), R"(The render mesh's deformed positions and normals, ((V, 3), (V, 3)) float32: new
arrays, or written into out=(positions, normals). ValueError for a model without a render mesh.)")
      .def("__repr__", [](const Instance& self) {
        return std::string("quiver.Instance(") + qv_integrator_name(self.config.integrator) + ", " +
               qv_solver_name(self.config.solver) + ", r=" + std::to_string(self.model->info().r) + (self.config.free_flight ? ", flying" : "") + ")";
      });

  m.def("step_many", &stepMany, py::arg("instances"), py::arg("threads") = 1,
        R"(Steps many instances of one Model once each (qv_instances_step): implicit Newmark StVK instances in groups
of 16 evaluated together (SIMD across instances), the rest as alone. States agree with Instance.step to
rounding (1e-9 of the largest coordinate after 2 s of changing loads on the suite's bar), not bit for
bit, and do not depend on `threads` when every instance is groupable. threads > 1 runs the groups on
that many threads (made for the call). The GIL is released while stepping. Returns each one's
StepStatus. Instances in a World are refused: the world steps them.)");

  py::class_<World>(m, "World", R"(Flying instances that touch each other and the world's colliders (qv_world).

World(*, max_instances=64, max_contacts=4096, friction=0.5, restitution=0.0, sleep_speed=0.02, sleep_time=0.5):
friction and restitution between instances; a group of instances that could touch, all slower than sleep_speed
(m/s; 0: never) for sleep_time (s), falls asleep until something wakes it (Instance.asleep, Instance.wake()).
add(instance) puts a flying instance in (all with the same time step), remove(instance) takes it out; step()
steps every awake instance once and returns how many reset. The world keeps its instances alive.)")
      .def(py::init([](std::optional<int> maxInstances, std::optional<int> maxContacts, std::optional<double> friction,
                       std::optional<double> restitution, std::optional<double> sleepSpeed, std::optional<double> sleepTime) {
             qv_world_config c;
             qv_world_config_init(&c);
             c.max_instances = maxInstances.value_or(c.max_instances);
             c.max_contacts = maxContacts.value_or(c.max_contacts);
             c.friction = friction.value_or(c.friction);
             c.restitution = restitution.value_or(c.restitution);
             c.sleep_speed = sleepSpeed.value_or(c.sleep_speed);
             c.sleep_time = sleepTime.value_or(c.sleep_time);
             require(c.max_instances >= 1 && c.max_instances <= 65536, "max_instances must be between 1 and 65536");
             require(c.max_contacts >= 0 && c.max_contacts <= (1 << 20), "max_contacts must be between 0 and 1048576");
             require(c.friction >= 0 && std::isfinite(c.friction), "friction must be >= 0 and finite");
             require(c.restitution >= 0 && c.restitution <= 1, "restitution must be between 0 and 1");
             require(c.sleep_speed >= 0 && std::isfinite(c.sleep_speed), "sleep_speed must be >= 0 and finite");
             require(c.sleep_time >= 0 && std::isfinite(c.sleep_time), "sleep_time must be >= 0 and finite");
             return std::make_unique<World>(c);
           }),
           py::kw_only(), py::arg("max_instances") = py::none(), py::arg("max_contacts") = py::none(),
           py::arg("friction") = py::none(), py::arg("restitution") = py::none(), py::arg("sleep_speed") = py::none(),
           py::arg("sleep_time") = py::none())
      .def("add", [](World& self, py::object instance) {
        if (!py::isinstance<Instance>(instance)) throw py::type_error("World.add takes a quiver.Instance");
        Instance& s = instance.cast<Instance&>();
        if (!s.config.free_flight) throw py::value_error("only flying instances (free_flight=True) go in a World");
        if (s.world) throw py::value_error("the instance is already in a World");
        if (static_cast<int>(self.instances.size()) == self.config.max_instances)
          throw py::value_error("the world is full (max_instances=" + std::to_string(self.config.max_instances) + ")");
        if (!self.instances.empty() && self.instances[0].cast<Instance&>().config.time_step != s.config.time_step)
          throw py::value_error("every instance of a World must have the same time step");
        int index = -1;
        if (qv_world_add(self.use(), s.use(), &index) != QV_OK) throw py::value_error("qv_world_add refused the instance");
        s.world = &self;
        self.instances.push_back(std::move(instance));
        return index;
      }, py::arg("instance"), "Adds a flying instance; returns its index (as contacts name it).")
      .def("remove", [](World& self, py::object instance) {
        if (!py::isinstance<Instance>(instance)) throw py::type_error("World.remove takes a quiver.Instance");
        Instance& s = instance.cast<Instance&>();
        if (s.world != &self) throw py::value_error("the instance is not in this World");
        if (qv_world_remove(self.use(), s.use()) != QV_OK) throw py::value_error("qv_world_remove refused the instance");
        s.world = nullptr;
        for (auto it = self.instances.begin(); it != self.instances.end(); ++it)
          if (it->is(instance)) {
            self.instances.erase(it);
            break;
          }
      }, py::arg("instance"),
           "Takes an instance out (a despawned object): the later ones move down an index, the others' contacts carry "
           "on, and what slept with it wakes. It keeps its state, awake, and can be stepped alone or added again.")
      .def_property_readonly("instances", [](const World& self) {
        py::list out;
        for (const py::object& s : self.instances) out.append(s);
        return out;
      })
      .def("__len__", [](const World& self) { return self.instances.size(); })
      .def("set_colliders", [](World& self, py::handle colliders) {
        ColliderSet set = ColliderSet::from(colliders);
        if (qv_world_set_colliders(self.use(), set.raw.data(), static_cast<int>(set.raw.size())) != QV_OK)
          throw py::value_error("qv_world_set_colliders refused the colliders");
        self.colliders = std::move(set);
      }, py::arg("colliders"), "The world's colliders (a list; copied: to move one, pass a new list).")
      .def("step", [](World& self, int threads) {
        if (threads < 1) throw py::value_error("threads must be at least 1");
        std::vector<Instance*> members;
        for (const py::object& s : self.instances) members.push_back(&s.cast<Instance&>());
        qv_world* world = self.use();
        BusyGuard guard(members);
        const qv_job_runner runner{threads, runOnThreads, nullptr};
        struct Stepping {  // the world's own colliders and members must not change meanwhile
          World& w;
          ~Stepping() { w.busy = false, qv_world_set_jobs(w.get(), nullptr); }
        } stepping{self};
        self.busy = true;
        if (threads > 1) qv_world_set_jobs(world, &runner);
        py::gil_scoped_release release;
        return qv_world_step(world);
      }, py::arg("threads") = 1,
           "Steps every awake instance once; returns how many reset (never expected). threads > 1 runs each "
           "instance's own parts of the step and the contact solve's islands on that many threads (made for the "
           "call; the same bits).")
      .def("contacts", [](const World& self) { return contactArray(static_cast<const qv_world*>(self.use()), qv_world_contacts); },
           "The last step's contacts, as Instance.contacts(); `instance` and `other` say who touched whom.")
      .def("save_snapshot", [](const World& self) {
        return saveSnapshot(qv_world_snapshot_size(self.use()), [&](void* data) { return qv_world_save_snapshot(self.use(), data); });
      }, "Every instance's snapshot, whether it sleeps, and the contacts between them, as bytes: restoring them and "
         "repeating the same calls repeats the same bits (the colliders are the caller's to restore).")
      .def("restore_snapshot", [](World& self, const py::bytes& snapshot) {
        restoreSnapshot(snapshot, "this world's", qv_world_snapshot_size(self.use()), [&](const void* data, size_t size) {
          return qv_world_restore_snapshot(self.use(), data, size);
        });
      }, py::arg("snapshot"));
}

} // namespace quiver_python
