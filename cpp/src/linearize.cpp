#include "servohydraulics/linearize.hpp"

namespace servohydraulics {

LinearModel linearize(const Dynamics& dyn, const State& y0, double u0) {
  const int n = dyn.num_states();
  LinearModel lm;
  lm.A.resize(n, n);
  lm.B.resize(n);
  lm.C.resize(LinearModel::kOutputs, n);
  lm.D.resize(LinearModel::kOutputs);
  const Dynamics::Input in{u0, 0.0};
  Jacobian J;
  State B;
  dyn.jacobian(y0.data(), in, J, &B);
  Output out;
  Dynamics::OutputGradients G;
  dyn.outputs(y0.data(), in, out, &G);
  for (int i = 0; i < n; ++i) {
    lm.B(i) = B[i];
    for (int j = 0; j < n; ++j) lm.A(i, j) = J[i][j];
  }
  for (int r = 0; r < LinearModel::kOutputs; ++r) {
    lm.D(r) = G[r][kMaxStates];
    for (int j = 0; j < n; ++j) lm.C(r, j) = G[r][j];
  }
  const bool actuator = dyn.mode() != ControlMode::Free;
  const bool valve = actuator && dyn.rig().effects.servovalve_dynamics;
  lm.active = {true, true, actuator, valve, valve, dyn.lugre()};
  lm.active.resize(static_cast<std::size_t>(n), true);  // the appended states are active by construction
  return lm;
}

}  // namespace servohydraulics
