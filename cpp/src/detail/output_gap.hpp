// Internal: the measure both integrator checks share (dopri5's check of a run that turned stiff,
// RK4's companion): how far a companion run's checked values (OdeSystem::checked_values: the
// displacement and load-cell force of the single plant; every actuator's stroke and force of the
// multi-actuator rig) are from the result's, relative to the result's peaks so far: the accuracy
// the methods state is of the peaks.
#pragma once

#include <algorithm>
#include <cmath>

#include "detail/ode_system.hpp"

namespace servohydraulics::detail {

template <class System>
class OutputGap {
 public:
  using Sys = OdeSystem<System>;
  using State = typename Sys::State;
  using Input = typename Sys::Input;

  //! The least peaks the gap is measured against: kFloor of the checked values' scales
  //! (OdeSystem::checked_scales: the stroke; the force of state_scale's pressure over the piston).
  //! Early in a run the signals and the peaks start near zero while the two runs differ by their
  //! tolerances' noise.  A run whose peak stays below the floor (1e-4 of the rig's scale: 13 um of
  //! a 127 mm stroke) is judged against the floor; any larger run is judged at least as strictly
  //! as against its final peak, since the running peak never exceeds the final one.
  static constexpr double kFloor = 1e-4;

  explicit OutputGap(const System& sys) noexcept : m_(Sys::checked(sys)) {
    Sys::checked_scales(sys, floor_);
    for (int j = 0; j < m_; ++j) floor_[j] *= kFloor;
  }

  void reset() noexcept {
    for (int j = 0; j < m_; ++j) peak_[j] = gap_[j] = 0.0;
  }

  //! Raises the peaks to y's checked values.
  void track(const System& sys, const Input& in, const State& y) noexcept {
    double v[Sys::kMaxChecked];
    Sys::checked_values(sys, y.data(), in, v);
    raise(v);
  }

  //! How far the band of states around the result reaches (in gaps y - yc): kBand = 2.
  static constexpr double kBand = 2.0;

  //! Raises the peaks to y's, then returns the largest gap of the result y and the companion yc
  //! relative to the peaks (NaN if either is not finite).  A checked value's gap is the larger of
  //! |v_j - vc_j| and its curvature over the band of states y +- kBand (y - yc) the result's error
  //! may reach, |v_j(y+) + v_j(y-) - 2 v_j(y)| / 2: a value that jumps inside that band (the
  //! load-cell force through a near-Coulomb friction's sign at a velocity reversal: 2 F_c between
  //! v = -1 mm/s and +1 mm/s) is as uncertain as the jump, even when both runs land on the same
  //! side (a high-gain rig's reversal, 10 % off in both RK4 and its companion); a smooth value has
  //! no curvature to speak of there (second order in the gap).
  double gap(const System& sys, const Input& in, const State& y, const State& yc) noexcept {
    double v[Sys::kMaxChecked], vc[Sys::kMaxChecked], d[Sys::kMaxChecked];
    double vp[Sys::kMaxChecked], vm[Sys::kMaxChecked];
    Sys::checked_values(sys, y.data(), in, v);
    Sys::checked_values(sys, yc.data(), in, vc);
    State yp = y, ym = y;
    for (std::size_t i = 0; i < y.size(); ++i) {
      const double e = kBand * (y[i] - yc[i]);
      yp[i] = y[i] + e;
      ym[i] = y[i] - e;
    }
    Sys::checked_values(sys, yp.data(), in, vp);
    Sys::checked_values(sys, ym.data(), in, vm);
    raise(v);
    for (int j = 0; j < m_; ++j) {
      // (a non-finite curvature, a band outside the model's domain, leaves the plain gap: std::max)
      d[j] = std::max(std::fabs(v[j] - vc[j]), 0.5 * std::fabs(vp[j] + vm[j] - 2.0 * v[j]));
      if (!(d[j] <= gap_[j])) gap_[j] = std::isnan(gap_[j]) ? gap_[j] : d[j];  // a NaN sticks
    }
    return relative(d);
  }

  //! The gap of values already computed: v the result's checked values, vc the companion's (the
  //! whole-record check, record.cpp); raises the peaks to v's and returns the largest plain
  //! |v_j - vc_j| / peak_j (no band: the states are not at hand).
  double gap_values(const double* v, const double* vc) noexcept {
    double d[Sys::kMaxChecked];
    raise(v);
    for (int j = 0; j < m_; ++j) {
      d[j] = std::fabs(v[j] - vc[j]);
      if (!(d[j] <= gap_[j])) gap_[j] = std::isnan(gap_[j]) ? gap_[j] : d[j];  // a NaN sticks
    }
    return relative(d);
  }

  //! The run's verdict so far: the largest gaps since the reset relative to the peaks so far (at
  //! the end of a run, its peaks: the measure of the stated accuracy, which a sample's gap, against
  //! the peak up to that sample, can only overstate; NaN if a gap was).
  double run_gap() const noexcept { return relative(gap_); }

 private:
  double relative(const double* d) const noexcept {
    double r = 0.0;
    for (int j = 0; j < m_; ++j) {
      const double g = d[j] / std::max(peak_[j], floor_[j]);
      if (std::isnan(g)) return g;
      r = std::max(r, g);
    }
    return r;
  }
  void raise(const double* v) noexcept {
    for (int j = 0; j < m_; ++j) peak_[j] = std::max(peak_[j], std::fabs(v[j]));
  }

  int m_;                                // the checked values (Sys::checked)
  double floor_[Sys::kMaxChecked] = {};  // their least peaks
  double peak_[Sys::kMaxChecked] = {};   // the result's largest |value| so far
  double gap_[Sys::kMaxChecked] = {};    // the largest gaps so far
};

}  // namespace servohydraulics::detail
