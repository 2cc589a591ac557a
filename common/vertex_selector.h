#pragma once
// Geometric vertex selection for fixed (Dirichlet) vertices and load groups.
//
// Grammar: clause ('&' clause)*, where a clause is AXIS OP VALUE with AXIS in x, y, z, OP in
// < <= > >=, and VALUE a number, optionally relative to the mesh's bounding box: "min+0.01",
// "max-0.5", "min", "max". Or the single clause "box:x0,y0,z0,x1,y1,z1" (inclusive).
// Examples: "x<0.01", "y>=max-1e-6", "x<min+0.05 & z>0.5".
#include <string>
#include <vector>

#include "common/tet_mesh.h"

namespace quiver {

class VertexSelector {
public:
  // Throws std::invalid_argument naming the selector and the position of the problem.
  explicit VertexSelector(const std::string& expression);

  // Indices of the vertices of `mesh` the expression selects, ascending.
  std::vector<int> select(const TetMesh& mesh) const;
  const std::string& expression() const { return expression_; }

private:
  struct Clause {
    int axis;        // 0, 1, 2
    int op;          // 0: <, 1: <=, 2: >, 3: >=
    int relativeTo;  // -1: absolute, 0: bbox min, 1: bbox max
    double value;
  };
  std::string expression_;
  std::vector<Clause> clauses_;
};

} // namespace quiver
