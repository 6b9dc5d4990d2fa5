// Internal: the measure both integrator checks share (dopri5's check of a run that turned stiff,
// RK4's companion): how far a companion run's displacement and load-cell force are from the
// result's, relative to the result's peaks so far: the accuracy the methods state is of the peaks.
#pragma once

#include <algorithm>
#include <cmath>

#include "servohydraulics/dynamics.hpp"
#include "servohydraulics/solver_options.hpp"

namespace servohydraulics::detail {

class OutputGap {
 public:
  //! The least peaks the gap is measured against: kFloor of the rig's displacement and force
  //! scales (the half-stroke; the force of state_scale's pressure over the piston).  Early in a run
  //! the signals and the peaks start near zero while the two runs differ by their tolerances' noise.
  //! A run whose peak stays below the floor (1e-4 of the rig's scale: 13 um of a 127 mm half-stroke)
  //! is judged against the floor; any larger run is judged at least as strictly as against its
  //! final peak, since the running peak never exceeds the final one.
  static constexpr double kFloor = 1e-4;

  explicit OutputGap(const Dynamics& dyn) noexcept
      : floor_x_(kFloor * state_scale(dyn, kX)), floor_f_(kFloor * state_scale(dyn, kP) * dyn.rig().A) {}

  void reset() noexcept { peak_x_ = peak_f_ = gap_x_ = gap_f_ = 0.0; }

  //! Raises the peaks to y's displacement and force.
  void track(const Dynamics& dyn, const Dynamics::Input& in, const State& y) noexcept {
    Output o;
    dyn.outputs(y.data(), in, o);
    raise(o);
  }

  //! Raises the peaks to y's, then returns max(|x - x_c| / peak_x, |F - F_c| / peak_f) of the
  //! result y and the companion yc (NaN if either is not finite).
  double gap(const Dynamics& dyn, const Dynamics::Input& in, const State& y, const State& yc) noexcept {
    Output o, oc;
    dyn.outputs(y.data(), in, o);
    dyn.outputs(yc.data(), in, oc);
    raise(o);
    const double dx = std::fabs(o.displacement - oc.displacement), df = std::fabs(o.force - oc.force);
    if (!(dx <= gap_x_)) gap_x_ = std::isnan(gap_x_) ? gap_x_ : dx;  // a NaN sticks
    if (!(df <= gap_f_)) gap_f_ = std::isnan(gap_f_) ? gap_f_ : df;
    return relative(dx, df);
  }

  //! The run's verdict so far: the largest gaps since the reset relative to the peaks so far (at
  //! the end of a run, its peaks: the measure of the stated accuracy, which a sample's gap, against
  //! the peak up to that sample, can only overstate; NaN if a gap was).
  double run_gap() const noexcept { return relative(gap_x_, gap_f_); }

 private:
  double relative(double dx, double df) const noexcept {
    const double gx = dx / std::max(peak_x_, floor_x_), gf = df / std::max(peak_f_, floor_f_);
    return std::isnan(gx) || std::isnan(gf) ? gx + gf : std::max(gx, gf);
  }
  void raise(const Output& o) noexcept {
    peak_x_ = std::max(peak_x_, std::fabs(o.displacement));
    peak_f_ = std::max(peak_f_, std::fabs(o.force));
  }

  double floor_x_, floor_f_;
  double peak_x_ = 0.0, peak_f_ = 0.0;  // the result's largest |displacement| [m] and |force| [N] so far
  double gap_x_ = 0.0, gap_f_ = 0.0;    // the largest gaps so far [m], [N]
};

}  // namespace servohydraulics::detail
