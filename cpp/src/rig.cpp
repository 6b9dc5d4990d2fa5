#include "servohydraulics/rig.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "servohydraulics/elements/mr_damper.hpp"
#include "servohydraulics/parameters.hpp"
#include "servohydraulics/state.hpp"

namespace servohydraulics {

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

// A table the interpolation can index: at least 2 points and as many flows as
// openings.  eval/slope/inverse are noexcept and on the hot path, so a table
// that is not (assigned field by field and never validated) gives NaN, which
// the integrators report as a NonFinite status, never an out-of-bounds read;
// the Python binding validates before it calls them (ValueError naming the field).
bool indexable(const FlowCurve& fc) noexcept { return fc.opening.size() >= 2 && fc.flow.size() == fc.opening.size(); }
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

double FlowCurve::eval(double x) const noexcept {
  const double a = std::fabs(x);
  double g;
  if (kind == Kind::Rational) {
    g = a / (1.0 + b * a);
  } else {
    if (!indexable(*this)) return kNaN;
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
  if (!indexable(*this)) return kNaN;
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
    if (!indexable(*this)) return kNaN;
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
    const std::string at = "[" + std::to_string(i) + "]";
    require(std::isfinite(opening[i]) && opening[i] > opening[i - 1], ("flow_curve.opening" + at).c_str(), opening[i],
            "must be finite and strictly increasing");
    require(std::isfinite(flow[i]) && flow[i] > flow[i - 1], ("flow_curve.flow" + at).c_str(), flow[i],
            "must be finite and strictly increasing (the curve must be invertible)");
  }
}

const char* bound_text(Bound b) noexcept {
  switch (b) {
    case Bound::Positive: return "finite and > 0";
    case Bound::NonNegative: return "finite and >= 0";
    case Bound::AtLeastOne: return "finite and >= 1";
    case Bound::PadeOrder: return "an integer in 1..6";
    case Bound::Finite: return "finite";
  }
  return "";
}

bool within(Bound b, double v) noexcept {
  switch (b) {
    case Bound::Positive: return finite_positive(v);
    case Bound::NonNegative: return finite_nonneg(v);
    case Bound::AtLeastOne: return std::isfinite(v) && v >= 1.0;
    case Bound::PadeOrder: return std::isfinite(v) && v >= 1.0 && v <= kMaxPadeOrder && v == std::floor(v);
    case Bound::Finite: return std::isfinite(v);
  }
  return false;
}

void Rig::validate() const {
  for (const ParameterInfo& p : kRigParameters) {
    const double v = this->*p.member;
    if (within(p.bound, v)) continue;
    const std::string requirement = std::string(p.doc) + " must be " + bound_text(p.bound) + " [" + p.unit + "]";
    require(false, p.key, v, requirement.c_str());
  }
  validate_mr_law(*this);
  flow_curve.validate();
}

}  // namespace servohydraulics
