// What every physical element of the plant shares: the evaluation it writes into, where it
// acts, and the rest point it starts from.  The element concept (one struct per element,
// folded over by Dynamics like pinocchio's joint collection) is described in
// elements.hpp and docs/architecture.md ("Add an element").
#pragma once

#include "servohydraulics/state.hpp"

namespace servohydraulics {

//! Capacity of a gradient row: the states' columns and one more, index num_states(), for the
//! derivative by the command u.
constexpr int kGradientCapacity = kMaxStates + 1;

//! Intermediate quantities of one evaluation of the plant (Dynamics::evaluate), with their
//! gradients by the active states and u (columns 0..num_states(), only the first W set).
//! An element adds to the specimen force (Fsp, dFsp) or turns the drive into the delayed
//! drive (vdrive), and writes the rates of its own states into rate[i], drate[i] (i its
//! state indices; it zeroes the first W entries of its rows itself).
struct Algebra {
  static constexpr int kCap = kGradientCapacity;
  double a = 0, da[kCap];          // acceleration and its gradient
  double F = 0, dF[kCap];          // load-cell force
  double drive = 0, ddrive[kCap];  // valve drive after saturation
  double s = 0, ds[kCap];          // metering opening after saturation
  double Q = 0, dQ[kCap];          // valve flow
  double pdot = 0, dpdot[kCap];
  double xvdd = 0, dxvdd[kCap];
  double zdot = 0, dzdot[kCap];    // rate of the bristle state kZ (a friction law's, LuGre; else 0)
  double Fsp = 0, dFsp[kCap];      // specimen force (the structure elements')
  double vdrive = 0, dvdrive[kCap];  // the drive as the valve sees it (after a drive element)
  double held = 0;                 // the forces on the structure but the exact Coulomb law's [N]
  double rate[kMaxStates];              // rates of the elements' states (by state index)
  double drate[kMaxStates][kCap];       // and their gradients
  bool drive_sat = false, spool_sat = false;
  // Zeroes the first W entries of the gradients of the paper plant (and of the specimen force,
  // read by outputs()); the elements zero their rows when on.
  template <int W>
  void zero() noexcept {
    for (int j = 0; j < W; ++j) {
      da[j] = dF[j] = ddrive[j] = ds[j] = dQ[j] = 0.0;
      dpdot[j] = dxvdd[j] = dzdot[j] = dFsp[j] = 0.0;
    }
  }
};

//! Where an element acts on the plant.
enum class Port {
  Structure,  //!< a force in parallel with the structure (Eq 5), reported as specimen_force
  Drive,      //!< on the valve drive between the controller (Eq 1) and the valve (Eq 2)
};

//! A structure law's force on the structure (Eq 5) and its partial derivatives by the base
//! states it reads: x, v and the bristle deflection z (StructureLaws, elements.hpp).
struct LawForce {
  double F = 0.0, dF_dx = 0.0, dF_dv = 0.0, dF_dz = 0.0;
};

//! The static force of a law that has none at rest (friction, damping): -0.0, the identity of
//! floating-point addition, so that the sum of the laws' static forces is the spring's to the bit.
constexpr double kNoStaticForce = -0.0;

//! The plant at rest, from which an element sets its states (Dynamics::equilibrium).
struct RestPoint {
  double x = 0.0;      //!< displacement [m]
  double spool = 0.0;  //!< the spool opening that feeds the leakage [-] (0 in free mode)
};

//! Copies an element's gradient rows (its states offset .. offset + count - 1) into the rows of J
//! (columns 0..n-1) and of B (column ku, the command's): an element's jacobian() for rows it
//! evaluates in full.
inline void copy_rows(const Algebra& g, int offset, int count, int n, int ku, Jacobian& J, State* B) noexcept {
  for (int i = offset; i < offset + count; ++i) {
    for (int j = 0; j < n; ++j) J[i][j] = g.drate[i][j];
    if (B) (*B)[i] = g.drate[i][ku];
  }
}

}  // namespace servohydraulics

//! Instantiates E::eval for every gradient width Dynamics dispatches on (kNumStates + 1 ..
//! kMaxStates + 1) and for width 0 (the values alone: Dynamics::rhs, no gradient entry written);
//! one line at the end of each element's .cpp.
#define SH_ELEMENT_EVAL_WIDTHS(E)                                                  \
  static_assert(::servohydraulics::kGradientCapacity == 17, "one width per case"); \
  template void E::eval<0>(const double*, int, Algebra&) const noexcept;           \
  template void E::eval<7>(const double*, int, Algebra&) const noexcept;           \
  template void E::eval<8>(const double*, int, Algebra&) const noexcept;           \
  template void E::eval<9>(const double*, int, Algebra&) const noexcept;           \
  template void E::eval<10>(const double*, int, Algebra&) const noexcept;          \
  template void E::eval<11>(const double*, int, Algebra&) const noexcept;          \
  template void E::eval<12>(const double*, int, Algebra&) const noexcept;          \
  template void E::eval<13>(const double*, int, Algebra&) const noexcept;          \
  template void E::eval<14>(const double*, int, Algebra&) const noexcept;          \
  template void E::eval<15>(const double*, int, Algebra&) const noexcept;          \
  template void E::eval<16>(const double*, int, Algebra&) const noexcept;          \
  template void E::eval<17>(const double*, int, Algebra&) const noexcept
