#pragma once
// Scripted scenarios for `quiver sim` (the runtime on a .qvr) and `quiver full` (the full-space
// reference on a mesh): pull a vertex group with a force, or drag and twist it with penalty springs,
// for some steps, release, optionally under gravity; write what happens. One script drives both,
// so their outputs compare like for like.
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "apps/support/flight_world.h"
#include "apps/support/step_settings.h"
#include "common/tet_mesh.h"

namespace quiver::app {

struct SimOptions {
  int steps = 300;                      // total steps
  int holdSteps = 100;                  // steps the load acts before release
  std::string group = "x>max-1e-6";     // vertex selector (common/vertex_selector.h) for the loaded group
  std::vector<double> force{0, 0, 0};   // N, total force spread over the group (pull mode)
  std::vector<double> drag{0, 0, 0};    // m, group targets moved by this much (drag mode)
  double twist = 0;                     // degrees about `axis` through the group's centre (drag mode)
  std::string axis = "x";               // x | y | z: the twist axis
  double stiffness = 1e4;               // N/m per vertex, drag mode's penalty springs
  bool gravity = false;                 // add g = 9.81 m/s^2 along -z
  FlightSetup flight;                   // --free (step.freeFlight): where the bodies start, what they touch
  StepSettings step;                    // integrator, elasticity, time step, Newton iterations per step
                                        // (runtime; full space: at most), Rayleigh damping
  std::string output;                   // NAME: NAME.pvd, NAME_NNNNN.vtu (a pile: NAME_NNNNN_K.vtu, body K), NAME.csv,
                                        // and a render mesh's NAME_render.pvd, NAME_render_NNNNN[_K].vtu; "" for none
  int every = 1;                        // write every k-th step
  bool json = false;                    // print one JSON summary instead of text
  std::string scenarioFile;             // --scenario: expanded before parsing (apps/support/scenario_file.h)

  // The scenario: loads, their timing, the integrator's settings (shared by sim, full and render).
  void addScenarioTo(CLI::App& app);
  // The scenario and what `sim` and `full` write: -o, --every, --json.
  void addTo(CLI::App& app);
  bool hasLoad() const;
  // "" when a scenario file may set `name = value` (an option addScenarioTo defines, with a value
  // it takes), otherwise what is wrong.
  static std::string checkScenarioOption(const std::string& name, const std::string& value);
};

// What a scenario drives: the runtime's instance or the full-space simulator.
class ScenarioTarget {
public:
  virtual ~ScenarioTarget() = default;
  virtual void addVertexForce(int vertex, const double force[3]) = 0;
  virtual void setGravity(const double acceleration[3]) = 0;
  // Free flight from the options' position, velocity and angular velocity; throws where the target cannot fly.
  virtual void startFlight(const SimOptions& options) = 0;
  virtual void setSprings(const std::vector<int>& vertices, const std::vector<double>& targets, double stiffness) = 0;
  virtual void clearSprings() = 0;
  // Advances one step; returns a status for the CSV (0 ok) and counts Newton iterations.
  virtual int step(int& newtonIterations) = 0;
  virtual int bodyCount() const { return 1; }  // a --pile flies more
  virtual void displacement(int body, std::vector<double>& u) const = 0;  // 3 per vertex, from the rest shape
  // A render mesh's triangles (none: the target has none) and a body's positions and normals on it.
  virtual std::vector<unsigned> renderTriangles() const { return {}; }
  virtual void renderFrame(int /*body*/, std::vector<float>& /*positions*/, std::vector<float>& /*normals*/) const {}
  virtual void energies(double& kinetic, double& elastic) const = 0;
  virtual double timeStep() const = 0;
};

struct ScenarioResult {
  std::vector<double> stepMicros;
  long newtonIterations = 0;
  int failedSteps = 0;  // resets (runtime) — the scenario goes on
  double lowestElastic = 0;  // the lowest elastic energy after a step, J, and that step (1-based; 0: none below 0)
  int lowestElasticStep = 0;
  double largestEnergy = 0;  // the largest kinetic + |elastic| after a step, J
};

// A warning when the elastic energy went negative beyond rounding (1e-6 of the largest energy):
// no St.Venant-Kirchhoff energy (nor a linear one) is ever negative, so the model's is not one.
// Empty otherwise.
std::string negativeEnergyWarning(const ScenarioResult& result);

// The vertices of `mesh` that the --group `selector` picks; throws naming --group if it is malformed or picks none.
std::vector<int> selectGroup(const TetMesh& mesh, const std::string& selector);

// Runs the scenario on `target` over `mesh` (rest shape, and tets for the .vtu frames), calling
// `afterStep` (if given) with the number of steps taken so far: 0 once set up, then after each step.
ScenarioResult runScenario(ScenarioTarget& target, const TetMesh& mesh, const SimOptions& options,
                           const std::function<void(int)>& afterStep = {});

// Median and 99th percentile of step times, in microseconds.
double percentile(std::vector<double> values, double p);

// `quiver sim MODEL.qvr`: returns the exit code.
int simulateModel(const std::string& modelPath, const SimOptions& options);

// `quiver sim MODEL.qvr --instances N`: a crowd of one model stepped together per frame.
struct CrowdOptions {
  int instances = 0;      // 0: one instance, the scenario as above
  int threads = 1;        // the caller's thread included
  bool oneByOne = false;  // qv_instance_step on each, for comparison

  void addTo(CLI::App& app);
};
int simulateCrowd(const std::string& modelPath, const SimOptions& options, const CrowdOptions& crowd);

struct FullSpaceOptions {
  std::string solver = "ldlt";          // llt | ldlt | cg | lu
  MaterialOverride material;            // over the mesh file's materials
  std::string finalNpy;                 // save the final displacement (3N, the file's vertex order)
};

// `quiver full MESH`: the same scenario on the full-space reference; returns the exit code.
// `fileVertex` maps loaded vertices to the mesh file's order, `fileVertexCount` is N.
int simulateFullSpace(const TetMesh& mesh, const std::vector<int>& fileVertex, size_t fileVertexCount,
                      const std::vector<int>& fixed, const FullSpaceOptions& full, const SimOptions& options);

struct RenderOptions {
  std::string output;                  // NAME.png, NAME.gif or NAME_%04d.png (apps/render/frame_writer.h)
  std::vector<int> size{800, 500};     // pixels
  int modes = 0;                       // > 0: a grid of the first `modes` linear modes
  bool basis = false;                  // the grid shows basis vectors (columns of U) instead
  double amplitude = 0.1;              // grid: largest displacement, fraction of the model's diagonal
  int every = 2;                       // animated scenario: a frame every k-th step
  SimOptions scenario;                 // what happens before (or while) the model is drawn

  void addTo(CLI::App& app);
};

// `quiver render MODEL.qvr`: returns the exit code.
int renderModel(const std::string& modelPath, const RenderOptions& options);

} // namespace quiver::app
