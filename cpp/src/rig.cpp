#include "servohydraulics/rig.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace servohydraulics {

void require(bool ok, const char* field, double value, const char* requirement) {
  if (ok) return;
  std::ostringstream s;
  s.precision(10);
  s << "invalid " << field << " = " << value << ": " << requirement;
  throw Error(s.str());
}

namespace {
bool finite_positive(double v) { return std::isfinite(v) && v > 0.0; }
bool finite_nonneg(double v) { return std::isfinite(v) && v >= 0.0; }

// Index i with opening[i] <= a < opening[i+1], clamped to the last segment.
std::size_t segment(const std::vector<double>& xs, double a) noexcept {
  const auto it = std::upper_bound(xs.begin(), xs.end(), a);
  std::size_t i = static_cast<std::size_t>(it - xs.begin());
  i = i == 0 ? 0 : i - 1;
  return std::min(i, xs.size() - 2);
}
}  // namespace

double FlowCurve::eval(double x) const noexcept {
  const double a = std::fabs(x);
  double g;
  if (kind == Kind::Rational) {
    g = a / (1.0 + b * a);
  } else {
    const std::size_t i = segment(opening, a);
    const double s = (flow[i + 1] - flow[i]) / (opening[i + 1] - opening[i]);
    g = flow[i] + s * (a - opening[i]);
  }
  return std::copysign(g, x);
}

double FlowCurve::slope(double x) const noexcept {
  const double a = std::fabs(x);
  if (kind == Kind::Rational) {
    const double d = 1.0 + b * a;
    return 1.0 / (d * d);
  }
  const std::size_t i = segment(opening, a);
  return (flow[i + 1] - flow[i]) / (opening[i + 1] - opening[i]);
}

double FlowCurve::inverse(double q) const noexcept {
  const double a = std::fabs(q);
  double x;
  if (kind == Kind::Rational) {
    // a = x / (1 + b x)  ->  x = a / (1 - b a), valid for a < 1/b.
    const double amax = b > 0.0 ? (1.0 / b) * (1.0 - 1e-12) : a;
    const double aa = std::min(a, amax);
    x = aa / (1.0 - b * aa);
  } else {
    const auto it = std::upper_bound(flow.begin(), flow.end(), a);
    std::size_t i = static_cast<std::size_t>(it - flow.begin());
    i = i == 0 ? 0 : i - 1;
    i = std::min(i, flow.size() - 2);
    const double s = (opening[i + 1] - opening[i]) / (flow[i + 1] - flow[i]);
    x = opening[i] + s * (a - flow[i]);
  }
  return std::copysign(x, q);
}

void FlowCurve::validate() const {
  if (kind == Kind::Rational) {
    require(std::isfinite(b) && b >= 0.0, "flow_curve.b", b, "must be finite and >= 0");
    return;
  }
  require(opening.size() >= 2, "flow_curve.opening (length)", static_cast<double>(opening.size()),
          "a flow table needs at least 2 points");
  require(opening.size() == flow.size(), "flow_curve.flow (length)", static_cast<double>(flow.size()),
          "must have as many points as flow_curve.opening");
  require(opening[0] == 0.0, "flow_curve.opening[0]", opening[0], "must be 0");
  require(flow[0] == 0.0, "flow_curve.flow[0]", flow[0], "must be 0 (no flow at null)");
  for (std::size_t i = 1; i < opening.size(); ++i) {
    require(std::isfinite(opening[i]) && opening[i] > opening[i - 1], "flow_curve.opening[i]", opening[i],
            "must be finite and strictly increasing");
    require(std::isfinite(flow[i]) && flow[i] > flow[i - 1], "flow_curve.flow[i]", flow[i],
            "must be finite and strictly increasing (the curve must be invertible)");
  }
}

void Rig::validate() const {
  require(finite_positive(m), "m", m, "structure mass must be finite and > 0 [kg]");
  require(finite_nonneg(c), "c", c, "viscous damping must be finite and >= 0 [N s/m]");
  require(finite_positive(k), "k", k, "stiffness must be finite and > 0 [N/m]");
  require(finite_nonneg(k_2), "k_2", k_2, "softened stiffness must be finite and >= 0 [N/m]");
  require(finite_positive(x_contact), "x_contact", x_contact, "contact displacement must be finite and > 0 [m]");
  require(finite_nonneg(F_c), "F_c", F_c, "Coulomb friction must be finite and >= 0 [N]");
  require(finite_positive(v_stick), "v_stick", v_stick, "friction regularisation velocity must be finite and > 0 [m/s]");
  require(std::isfinite(stribeck_ratio) && stribeck_ratio >= 1.0, "stribeck_ratio", stribeck_ratio,
          "static to sliding friction ratio F_s / F_c must be finite and >= 1");
  require(finite_positive(v_s), "v_s", v_s, "Stribeck velocity must be finite and > 0 [m/s]");
  require(finite_positive(sigma_0), "sigma_0", sigma_0, "LuGre bristle stiffness must be finite and > 0 [N/m]");
  require(finite_nonneg(sigma_1), "sigma_1", sigma_1, "LuGre bristle damping must be finite and >= 0 [N s/m]");
  require(finite_nonneg(m_p), "m_p", m_p, "piston mass must be finite and >= 0 [kg]");
  require(finite_positive(A), "A", A, "piston area must be finite and > 0 [m^2]");
  require(finite_positive(K_a), "K_a", K_a, "compressibility coefficient must be finite and > 0 [m^5/N]");
  require(finite_nonneg(C_l), "C_l", C_l, "leakage coefficient must be finite and >= 0 [m^3/(s Pa)]");
  require(finite_positive(p_s), "p_s", p_s, "supply pressure must be finite and > 0 [Pa]");
  require(finite_positive(stroke), "stroke", stroke, "actuator half-stroke must be finite and > 0 [m]");
  require(finite_positive(F_cap), "F_cap", F_cap, "actuator capacity must be finite and > 0 [N]");
  require(finite_positive(K_v), "K_v", K_v, "flow gain must be finite and > 0 [m^3/s]");
  require(finite_positive(K_s), "K_s", K_s, "valve gain must be finite and > 0 [1/V]");
  require(finite_positive(f_v), "f_v", f_v, "servovalve natural frequency must be finite and > 0 [Hz]");
  require(finite_positive(zeta_v), "zeta_v", zeta_v, "servovalve damping ratio must be finite and > 0");
  require(finite_positive(x_v_max), "x_v_max", x_v_max, "spool opening limit must be finite and > 0 [-]");
  require(finite_positive(C_F_disp), "C_F_disp", C_F_disp, "conversion factor must be finite and > 0 [V/m]");
  require(finite_positive(C_F_force), "C_F_force", C_F_force, "conversion factor must be finite and > 0 [V/N]");
  require(finite_nonneg(G_p), "G_p", G_p, "proportional gain must be finite and >= 0");
  require(finite_nonneg(G_d), "G_d", G_d, "derivative gain must be finite and >= 0 [s]");
  require(finite_positive(v_max), "v_max", v_max, "drive limit must be finite and > 0 [V]");
  flow_curve.validate();
}

}  // namespace servohydraulics
