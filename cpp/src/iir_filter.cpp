#include "servohydraulics/iir_filter.hpp"

#include <cmath>
#include <complex>
#include <string>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

void IirCoefficients::validate() const {
  require(order <= kMaxOrder, "filter.order", static_cast<double>(order), "0 to 8");
  require(a[0] == 1.0, "filter.a[0]", a[0], "1 (normalised)");
  for (std::size_t i = 0; i <= order; ++i) {
    const std::string bn = "filter.b[" + std::to_string(i) + "]", an = "filter.a[" + std::to_string(i) + "]";
    require(std::isfinite(b[i]), bn.c_str(), b[i], "finite");
    require(std::isfinite(a[i]), an.c_str(), a[i], "finite");
  }
}

double IirCoefficients::dc_gain() const noexcept {
  double sb = 0.0, sa = 0.0;
  for (std::size_t i = 0; i <= order; ++i) {
    sb += b[i];
    sa += a[i];
  }
  return sb / sa;
}

IirCoefficients butterworth_lowpass(int order, double cutoff, double fs) {
  require(order >= 1 && order <= static_cast<int>(IirCoefficients::kMaxOrder), "butterworth.order",
          static_cast<double>(order), "1 to 8");
  require(std::isfinite(fs) && fs > 0.0, "butterworth.fs", fs, "finite and > 0 [Hz]");
  require(std::isfinite(cutoff) && cutoff > 0.0 && cutoff < 0.5 * fs, "butterworth.cutoff", cutoff,
          "in (0, fs/2) [Hz]");
  // butter.m: prewarp with its own fs = 2 (u = 4 tan(pi Wn / 2)), the prototype poles scaled by u,
  // then the bilinear map z = (4 + p) / (4 - p); zeros at z = -1.  The gain makes the DC gain 1.
  const double Wn = cutoff / (0.5 * fs);
  const double u = 4.0 * std::tan(kPi * Wn / 2.0);
  std::array<std::complex<double>, IirCoefficients::kMaxOrder + 1> a{};  // polynomial in z^-1, ascending
  a[0] = 1.0;
  for (int k = 1; k <= order; ++k) {
    const std::complex<double> p = u * std::exp(std::complex<double>(0.0, kPi * (2.0 * k + order - 1) / (2.0 * order)));
    const std::complex<double> z = (4.0 + p) / (4.0 - p);
    for (int i = k; i >= 1; --i) a[i] -= z * a[i - 1];  // multiply by (1 - z z^-1)
  }
  IirCoefficients c;
  c.order = static_cast<std::size_t>(order);
  double sa = 0.0, sb = 0.0;
  double binom = 1.0;
  for (int i = 0; i <= order; ++i) {
    c.a[i] = a[i].real();
    c.b[i] = binom;  // (1 + z^-1)^n
    sa += c.a[i];
    sb += binom;
    binom = binom * (order - i) / (i + 1);
  }
  const double g = sa / sb;
  for (int i = 0; i <= order; ++i) c.b[i] *= g;
  c.a[0] = 1.0;
  return c;
}

IirFilter::IirFilter(const IirCoefficients& c) : c_(c) {
  c_.validate();
  reset();
}

IirFilter::IirFilter() noexcept {
  c_.b[0] = 1.0;
  c_.a[0] = 1.0;
}

}  // namespace servohydraulics
