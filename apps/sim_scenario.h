#pragma once
// `quiver sim`: a scripted scenario on the runtime library, as a game would drive it: pull (or drag
// and twist) a vertex group for some steps, release, optionally under gravity; write what happens.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace quiver::app {

struct SimOptions {
  int steps = 300;                      // total steps
  int holdSteps = 100;                  // steps the load acts before release
  std::string group = "x>max-1e-6";     // vertex selector (common/vertex_selector.h) for the loaded group
  std::vector<double> force{0, 0, 0};   // N, total force spread over the group (pull mode)
  std::vector<double> drag{0, 0, 0};    // m, group targets moved by this much (drag mode)
  double twist = 0;                     // degrees about the x axis through the group's centre (drag mode)
  double stiffness = 1e4;               // N/m per vertex, drag mode's penalty springs
  bool gravity = false;                 // add g = 9.81 m/s^2 along -z
  std::string integrator = "newmark";   // newmark | euler | central
  double timeStep = 0;                  // s; 0: the model's
  int newton = 1;                       // Newton iterations per step
  double alpha = -1, beta = -1;         // Rayleigh damping; negative: the model's
  std::string output;                   // NAME: NAME.pvd, NAME_NNNN.vtu, NAME.csv; "" for none
  int every = 1;                        // write every k-th step
  bool json = false;                    // print one JSON summary instead of text

  void addTo(CLI::App& app);
};

// Returns the process exit code; throws std::runtime_error on bad input.
int runScenario(const std::string& modelPath, const SimOptions& options);

} // namespace quiver::app
