#pragma once
// Isotropic linear-elastic material parameters for St.Venant-Kirchhoff.
#include <string>

namespace quiver {

struct Material {
  std::string name;           // as named in the mesh file or on the command line
  double youngsModulus = 1e6; // E, Pa, > 0
  double poissonRatio = 0.45; // nu, dimensionless, in (-1, 0.5)
  double density = 1000.0;    // rho, kg/m^3, > 0

  // Lamé parameters: lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
  double lambda() const { return youngsModulus * poissonRatio / ((1 + poissonRatio) * (1 - 2 * poissonRatio)); }
  double mu() const { return youngsModulus / (2 * (1 + poissonRatio)); }
};

// Returns an empty string when the parameters are physically admissible, else what is wrong.
std::string checkMaterial(const Material& m);

} // namespace quiver
