// Consumer of the installed C++ package: builds the paper's rig, holds a 1 mm
// displacement command for 2 s and checks that the piston settles where the
// closed form of Eq (12) at s = 0 says: with leakage C_l the static gain is
//   x/u = A K_v C_F K_s G_p / (C_l k + A K_v C_F K_s G_p)   (about 0.97),
// within 1e-3 relative (the nonlinear flow terms change it by ~1e-4 at 1 mm).
#include <cmath>
#include <cstdio>

#include <servohydraulics/plant.hpp>
#include <servohydraulics/presets.hpp>

int main() {
  namespace sh = servohydraulics;
  const sh::Rig rig = sh::zhao2003();
  sh::Plant plant(rig, sh::ControlMode::Displacement, 5e-4);
  sh::Output out;
  const double u = 1e-3;  // [m]
  for (int k = 0; k < 4000; ++k) {
    const sh::Status st = plant.step(u, out);
    if (!st.ok()) {
      std::fprintf(stderr, "step %d failed: %s at t = %g s\n", k, st.message(), st.t);
      return 1;
    }
  }
  const double loop = rig.A * rig.K_v * rig.C_F_disp * rig.K_s * rig.G_p;
  const double expected = u * loop / (rig.C_l * rig.k + loop);
  const double rel = std::fabs(out.displacement - expected) / expected;
  std::printf("x(2 s) = %.6f mm, closed form %.6f mm, relative difference %.2e\n", out.displacement * 1e3,
              expected * 1e3, rel);
  return rel < 1e-3 ? 0 : 1;
}
