// A discrete IIR filter b(z)/a(z) of low order in direct form II transposed (MATLAB's filter and
// Simulink's Discrete Filter block compute the same recursion), and MATLAB's butter(n, Wn) low-pass
// design, used by the maRTHS benchmark's RoDeAC compensator (marths/controllers.hpp: the 4th-order
// 20 Hz Butterworth noise filter of S3_Controller.m).  Construction validates (throws Error);
// reset(), step() and pending() are noexcept and allocation-free.
#pragma once

#include <array>
#include <cstddef>

namespace servohydraulics {

//! Coefficients of y_k + a_1 y_{k-1} + ... + a_n y_{k-n} = b_0 u_k + ... + b_n u_{k-n} (a_0 = 1).
struct IirCoefficients {
  static constexpr std::size_t kMaxOrder = 8;
  std::size_t order = 0;                   //!< n, 0 .. kMaxOrder
  std::array<double, kMaxOrder + 1> b{};   //!< b_0 .. b_n
  std::array<double, kMaxOrder + 1> a{};   //!< a_0 = 1, a_1 .. a_n
  void validate() const;
  double dc_gain() const noexcept;  //!< sum b / sum a
};

//! MATLAB's [b, a] = butter(order, cutoff / (fs / 2)): the analog Butterworth prototype scaled to the
//! prewarped cutoff 2 fs tan(pi cutoff / fs), mapped by the bilinear transform; unit DC gain.
//! cutoff [Hz] in (0, fs/2), fs [Hz] > 0, order 1 .. kMaxOrder.
IirCoefficients butterworth_lowpass(int order, double cutoff, double fs);

class IirFilter {
 public:
  explicit IirFilter(const IirCoefficients& c);
  IirFilter() noexcept;  //!< the identity (order 0, b_0 = 1)
  void reset() noexcept { z_.fill(0.0); }  //!< zero initial state
  //! y_k = b_0 u_k + z_0; then the state advances with u_k and y_k.
  double step(double u) noexcept {
    const std::size_t n = c_.order;
    const double y = c_.b[0] * u + z_[0];
    for (std::size_t i = 0; i + 1 < n; ++i) z_[i] = c_.b[i + 1] * u + z_[i + 1] - c_.a[i + 1] * y;
    if (n > 0) z_[n - 1] = c_.b[n] * u - c_.a[n] * y;
    return y;
  }
  //! The part of the next output that does not depend on the next input: y_k = b_0 u_k + pending().
  double pending() const noexcept { return z_[0]; }
  double feedthrough() const noexcept { return c_.b[0]; }  //!< b_0
  const IirCoefficients& coefficients() const noexcept { return c_; }

 private:
  IirCoefficients c_;
  std::array<double, IirCoefficients::kMaxOrder + 1> z_{};
};

}  // namespace servohydraulics
