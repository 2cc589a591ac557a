#pragma once
// A free bar (free_bar.h) started in flight under gravity among colliders, with what its contacts give.
#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "free_bar.h"
#include "runtime_fixture.h"

namespace quiver::test {

struct Dropped {
  FreeBar bar;
  std::unique_ptr<test::Instance> inst;
  std::vector<qv_collider> colliders;
  double h;
  Dropped(double step, std::vector<qv_collider> world, const qv_rigid_state& start, double alpha = 5,
          std::array<int, 3> cells = {6, 1, 1}, Eigen::Vector3d size = {0.6, 0.1, 0.1}, bool softContacts = false,
          qv_integrator integrator = QV_INTEGRATOR_IMPLICIT_NEWMARK, qv_solver solver = QV_SOLVER_MINIMIZE,
          int newtonIterations = 0)
      : bar(16, cells, size), colliders(world), h(step) {
    qv_instance_config c = bar.config(h);
    c.rayleigh_alpha = alpha;
    c.soft_contacts = softContacts ? 1 : 0;
    c.integrator = integrator;
    c.solver = solver;
    if (newtonIterations > 0) c.newton_iterations = newtonIterations;
    inst = std::make_unique<test::Instance>(bar.model, c);
    EXPECT_EQ(qv_instance_set_rigid_state(inst->s, &start), QV_OK);
    const double g[3] = {0, 0, -QV_STANDARD_GRAVITY};
    qv_instance_set_gravity(inst->s, g);
    EXPECT_EQ(qv_instance_set_colliders(inst->s, colliders.data(), static_cast<int>(colliders.size())), QV_OK);
  }
  qv_rigid_state state() const {
    qv_rigid_state s;
    qv_instance_get_rigid_state(inst->s, &s);
    return s;
  }
  // The last step's contact force (N) and deepest penetration (m, > 0 when penetrating).
  void contactForce(double force[3], double& penetration) const {
    std::vector<qv_contact> contacts(64);
    const int n = qv_instance_contacts(inst->s, contacts.data(), 64);
    force[0] = force[1] = force[2] = 0;
    penetration = 0;
    for (int j = 0; j < std::min(n, 64); ++j) {
      for (int a = 0; a < 3; ++a) force[a] += contacts[j].impulse[a] / h;
      penetration = std::max(penetration, -contacts[j].depth);
    }
  }
};

} // namespace quiver::test
