#include "servohydraulics/linearize.hpp"

namespace servohydraulics {

LinearModel linearize(const Dynamics& dyn, const State& y0, double u0) {
  LinearModel lm;
  const Dynamics::Input in{u0, 0.0};
  Jacobian J;
  State B;
  dyn.jacobian(y0.data(), in, J, &B);
  Output out;
  Dynamics::OutputGradients G;
  dyn.outputs(y0.data(), in, out, &G);
  for (int i = 0; i < kNumStates; ++i) {
    lm.B(i) = B[i];
    for (int j = 0; j < kNumStates; ++j) lm.A(i, j) = J[i][j];
  }
  for (int r = 0; r < LinearModel::kOutputs; ++r) {
    lm.D(r) = G[r][kNumStates];
    for (int j = 0; j < kNumStates; ++j) lm.C(r, j) = G[r][j];
  }
  const bool actuator = dyn.mode() != ControlMode::Free;
  const bool valve = actuator && dyn.rig().effects.servovalve_dynamics;
  lm.active = {true, true, actuator, valve, valve, dyn.lugre()};
  return lm;
}

}  // namespace servohydraulics
