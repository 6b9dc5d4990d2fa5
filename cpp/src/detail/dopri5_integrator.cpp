#include "detail/dopri5_integrator.hpp"

#include <algorithm>
#include <cmath>

#include "detail/small_lu.hpp"

namespace servohydraulics::detail {

namespace {
// Dormand & Prince (1980), "A family of embedded Runge-Kutta formulae", J. Comput. Appl. Math. 6:19-26,
// Table 2 (RK5(4)7M): the nodes, the stage weights, the 5th-order weights (row 7, FSAL) and e = b - b^.
constexpr double a21 = 1.0 / 5.0;
constexpr double a31 = 3.0 / 40.0, a32 = 9.0 / 40.0;
constexpr double a41 = 44.0 / 45.0, a42 = -56.0 / 15.0, a43 = 32.0 / 9.0;
constexpr double a51 = 19372.0 / 6561.0, a52 = -25360.0 / 2187.0, a53 = 64448.0 / 6561.0, a54 = -212.0 / 729.0;
constexpr double a61 = 9017.0 / 3168.0, a62 = -355.0 / 33.0, a63 = 46732.0 / 5247.0, a64 = 49.0 / 176.0,
                 a65 = -5103.0 / 18656.0;
constexpr double b1 = 35.0 / 384.0, b3 = 500.0 / 1113.0, b4 = 125.0 / 192.0, b5 = -2187.0 / 6784.0,
                 b6 = 11.0 / 84.0;
constexpr double e1 = 71.0 / 57600.0, e3 = -71.0 / 16695.0, e4 = 71.0 / 1920.0, e5 = -17253.0 / 339200.0,
                 e6 = 22.0 / 525.0, e7 = -1.0 / 40.0;
// Step-size controller: h_new = h * clamp(kSafety err^(-1/5), kShrink, kGrow).
constexpr double kSafety = 0.9, kShrink = 0.2, kGrow = 5.0;
}  // namespace

template <class System>
BasicDopri5Integrator<System>::BasicDopri5Integrator(const System& sys, double dt, const SolverOptions& opt,
                                                     const State& y_prime, bool checked)
    : n_(Sys::size(sys)),
      rtol_(opt.rtol),
      max_steps_(opt.max_steps_per_sample),
      stiff_steps_(opt.stiff_steps),
      dt_(dt),
      gap_(sys),
      h_(dt),
      rosenbrock_(opt.stiff_rosenbrock),
      rosenbrock_order_(opt.rosenbrock_order),
      stiffness_test_(opt.stiffness_test),
      h_rosenbrock_(dt) {
  Sys::tolerances(sys, opt, atol_);
  if (opt.stiff_fallback) {
    // Absolute tolerances 1e-2 of these cut the error on high-gain rigs ~7x but made one of 150
    // such rigs overrun max_steps_per_sample (10x the steps): the check below flags instead.
    implicit_ = std::make_unique<BasicCvodeIntegrator<System>>(sys, dt, opt, y_prime);
    if (checked && opt.stiff_check) {
      SolverOptions tight = opt;
      tight.rtol = opt.rtol / kShadowTighten;  // the absolute tolerances follow rtol
      shadow_ = std::make_unique<BasicDopri5Integrator>(sys, dt, tight, y_prime, false);
    }
  }
}

template <class System>
void BasicDopri5Integrator<System>::reset(const State& y, double t) noexcept {
  steps_done_ = rhs_done_ = restarts_ = stiff_samples_ = 0;
  fsal_ = false;
  h_ = dt_;
  h_rosenbrock_ = dt_;
  rosenbrock_failed_ = false;
  hold_ = 0;
  shadow_live_ = false;
  gap_.reset();
  if (implicit_) implicit_->reset(y, t);
  if (shadow_) shadow_->reset(y, t);
}

// The error of the result grows with its tolerance: the shadow, kShadowTighten times tighter, is
// off by less, so the gap between the two measures the result's error (kShadowGap).  The shadow
// follows the run from the state where its first stiff sample began to its end, explicit samples
// included: an error the loop amplifies from sample to sample, or one that a sharp event far from
// the stiff stretches makes (a force reversal), shows in the gap as it does in the result.
template <class System>
void BasicDopri5Integrator<System>::verify(const System& sys, const Input& in, const State& y_start,
                                           double t_start, const State& y, double t_next, Status& st) noexcept {
  if (!shadow_live_) {
    shadow_y_ = y_start;
    shadow_->reset(shadow_y_, t_start);
    shadow_live_ = true;
  }
  double ts = t_start;
  const Status s = shadow_->advance(sys, in, shadow_y_, ts, t_next);
  st.internal_steps += s.internal_steps;
  st.rhs_evals += s.rhs_evals;
  if (!s.ok()) {  // the tighter run failed (too much work) where the result did not: it restarts from the result
    shadow_y_ = y;
    shadow_->reset(shadow_y_, t_next);
    gap_.track(sys, in, y);
    st.run_error_estimate = gap_.run_gap() / (kShadowGap * kVerifyTolerance);
    return;
  }
  st.error_estimate = gap_.gap(sys, in, y, shadow_y_) / (kShadowGap * kVerifyTolerance);
  st.run_error_estimate = gap_.run_gap() / (kShadowGap * kVerifyTolerance);
  st.inaccurate = !(st.error_estimate <= 1.0);
}

template <class System>
double BasicDopri5Integrator<System>::trial_step(const System& sys, const Input& in, const State& y, double h,
                                                 State& y5) noexcept {
  State& k1 = k_[0];
  State tmp{};
  const int n = n_;
  for (int i = 0; i < n; ++i) tmp[i] = y[i] + h * a21 * k1[i];
  Sys::rhs(sys, tmp.data(), in, k_[1].data());
  for (int i = 0; i < n; ++i) tmp[i] = y[i] + h * (a31 * k1[i] + a32 * k_[1][i]);
  Sys::rhs(sys, tmp.data(), in, k_[2].data());
  for (int i = 0; i < n; ++i) tmp[i] = y[i] + h * (a41 * k1[i] + a42 * k_[1][i] + a43 * k_[2][i]);
  Sys::rhs(sys, tmp.data(), in, k_[3].data());
  for (int i = 0; i < n; ++i)
    tmp[i] = y[i] + h * (a51 * k1[i] + a52 * k_[1][i] + a53 * k_[2][i] + a54 * k_[3][i]);
  Sys::rhs(sys, tmp.data(), in, k_[4].data());
  for (int i = 0; i < n; ++i)
    tmp[i] = y[i] + h * (a61 * k1[i] + a62 * k_[1][i] + a63 * k_[2][i] + a64 * k_[3][i] + a65 * k_[4][i]);
  Sys::rhs(sys, tmp.data(), in, k_[5].data());
  if (stiffness_test_) ysti_ = tmp;
  for (int i = 0; i < n; ++i)
    y5[i] = y[i] + h * (b1 * k1[i] + b3 * k_[2][i] + b4 * k_[3][i] + b5 * k_[4][i] + b6 * k_[5][i]);
  Sys::rhs(sys, y5.data(), in, k_[6].data());
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double e = h * (e1 * k1[i] + e3 * k_[2][i] + e4 * k_[3][i] + e5 * k_[4][i] + e6 * k_[5][i] +
                          e7 * k_[6][i]);
    const double sc = atol_[i] + rtol_ * std::max(std::fabs(y[i]), std::fabs(y5[i]));
    sum += (e / sc) * (e / sc);
  }
  return std::sqrt(sum / n);  // NaN if a stage was not finite: rejected by the caller
}

template <class System>
typename BasicDopri5Integrator<System>::Outcome BasicDopri5Integrator<System>::explicit_sample(
    const System& sys, const Input& in, State& y, double& t, double t_next, Status& st) noexcept {
  if (!fsal_ || Sys::changed(in, fsal_in_)) {
    Sys::rhs(sys, y.data(), in, k_[0].data());
    ++st.rhs_evals;
  }
  fsal_ = false;
  int attempts = 0, stiff_count = 0, nonstiff_count = 0;
  bool rejected = false;
  State y5 = y;  // the entries past n_ (unused states) stay as they are
  while (t < t_next) {
    const double remaining = t_next - t;
    // Equal steps to the sample end: no sliver of a last step.
    const double n_left = std::ceil(remaining / std::min(h_, remaining) * (1.0 - 1e-12));
    const double h = remaining / std::max(1.0, n_left);
    if (++attempts > stiff_steps_ || h < 1e-12 * dt_) return Outcome::Stiff;
    if (attempts > max_steps_) return Outcome::TooMuchWork;
    const double err = trial_step(sys, in, y, h, y5);
    st.rhs_evals += 6;
    if (!(err <= 1.0)) {  // rejected (or NaN: a stage blew up)
      h_ = h * (std::isfinite(err) ? std::max(kShrink, kSafety * std::pow(err, -0.2)) : kShrink);
      rejected = true;
      continue;
    }
    const double fac = err > 0.0 ? std::min(kGrow, std::max(kShrink, kSafety * std::pow(err, -0.2))) : kGrow;
    h_ = std::min(dt_, h * (rejected ? std::min(1.0, fac) : fac));
    rejected = false;
    // Hairer's stiffness test (options.stiffness_test; their DOPRI5): h lambda ~ h |f(y5) - f(ysti)| /
    // |y5 - ysti|; kHairerStiff accepted steps above 3.25 (the stability boundary) in a sample, never 6 in a
    // row below it between them: stiff
    if (stiffness_test_) {
      double num = 0.0, den = 0.0;
      for (int i = 0; i < n_; ++i) {
        const double a = k_[6][i] - k_[5][i], b = y5[i] - ysti_[i];
        num += a * a;
        den += b * b;
      }
      if (den > 0.0 && h * std::sqrt(num / den) > 3.25) {
        nonstiff_count = 0;
        if (++stiff_count >= kHairerStiff) return Outcome::Stiff;
      } else if (++nonstiff_count >= 6) {
        stiff_count = 0;
      }
    }
    y = y5;
    k_[0] = k_[6];
    t = n_left <= 1.0 ? t_next : t + h;
    ++st.internal_steps;
  }
  fsal_ = true;
  fsal_in_ = in;
  return Outcome::Done;
}

// The error-controlled Rosenbrock methods' step control (rosenbrock_sample, rodas4_sample): the one-step
// method's step is carried from sample to sample, with no restart from order 1.
template <class System>
template <class Step, class Factor>
Status BasicDopri5Integrator<System>::rosenbrock_steps(State& y, double& t, double t_next, Step&& step,
                                                       Factor&& factor) noexcept {
  Status st;
  st.stiff = true;
  ++stiff_samples_;
  fsal_ = false;
  h_ = dt_;
  State yn{};
  long attempts = 0;
  at_size(n_, [&](auto size) {
    const int m = size;
    while (t < t_next) {
      const double remaining = t_next - t;
      const double n_left = std::ceil(remaining / std::min(h_rosenbrock_, remaining) * (1.0 - 1e-12));
      const double h = remaining / std::max(1.0, n_left);
      if (++attempts > kRosenbrockAttempts || h < 1e-14 * dt_) {
        st.code = Status::TooMuchWork;
        return;
      }
      const double err = step(size, h, yn, st);
      if (!(err <= 1.0)) {  // rejected (NaN: a stage blew up)
        h_rosenbrock_ = h * (std::isfinite(err) ? std::max(kShrink, kSafety * factor(err)) : kShrink);
        continue;
      }
      for (int i = 0; i < m; ++i) y[i] = yn[i];
      t = n_left <= 1.0 ? t_next : t + h;
      ++st.internal_steps;
      const double grow = err > 0.0 ? std::min(kGrow, std::max(kShrink, kSafety * factor(err))) : kGrow;
      h_rosenbrock_ = std::min(dt_, h * grow);
    }
  });
  return st;
}

// The stiff sample by Shampine and Reichelt's (1997, SIAM J. Sci. Comput. 18(1), "The MATLAB ODE
// suite", section 3) second-order Rosenbrock formula, L-stable, with its third-order error estimate,
// d = 1 / (2 + sqrt 2), W = I - h d J (the autonomous form: the input is held in a sample):
//   k1 = W^-1 F0,  F1 = f(y + h k1 / 2),  k2 = W^-1 (F1 - k1) + k1,  y+ = y + h k2,
//   F2 = f(y+),  k3 = W^-1 (F2 - e32 (k2 - F1) - 2 (k1 - F0)),  est = h (k1 - 2 k2 + k3) / 6,
// e32 = 6 + sqrt 2, weighed as dopri5's (atol_, rtol_); the step follows err^(-1/3).  A one-step
// method: the step proposed at a sample's end starts the next stiff sample, with no restart from order 1.
template <class System>
Status BasicDopri5Integrator<System>::rosenbrock_sample(const System& sys, const Input& in, State& y, double& t,
                                                        double t_next) noexcept {
  constexpr double kD = 0.29289321881345248;    // 1 / (2 + sqrt 2)
  constexpr double kE32 = 7.4142135623730951;   // 6 + sqrt 2
  State f0{}, f1{}, f2{}, k1{}, k2{}, k3{};
  double* W = W_.data();
  const auto step = [&](auto size, double h, State& yn, Status& st) {
    const int m = size;
    Sys::jacobian_rhs(sys, y.data(), in, W, f0.data());
    for (int i = 0; i < m * m; ++i) W[i] *= -kD * h;
    for (int i = 0; i < m; ++i) W[i + i * m] += 1.0;
    lu_factor(W, size, piv_.data());
    for (int i = 0; i < m; ++i) k1[i] = f0[i];
    lu_solve(W, size, piv_.data(), k1.data());
    for (int i = 0; i < m; ++i) yn[i] = y[i] + 0.5 * h * k1[i];
    Sys::rhs(sys, yn.data(), in, f1.data());
    for (int i = 0; i < m; ++i) k2[i] = f1[i] - k1[i];
    lu_solve(W, size, piv_.data(), k2.data());
    for (int i = 0; i < m; ++i) {
      k2[i] += k1[i];
      yn[i] = y[i] + h * k2[i];
    }
    Sys::rhs(sys, yn.data(), in, f2.data());
    for (int i = 0; i < m; ++i) k3[i] = f2[i] - kE32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i]);
    lu_solve(W, size, piv_.data(), k3.data());
    st.rhs_evals += 3;
    double sum = 0.0;
    for (int i = 0; i < m; ++i) {
      const double e = h / 6.0 * (k1[i] - 2.0 * k2[i] + k3[i]);
      const double sc = atol_[i] + rtol_ * std::max(std::fabs(y[i]), std::fabs(yn[i]));
      sum += (e / sc) * (e / sc);
    }
    return std::sqrt(sum / m);
  };
  return rosenbrock_steps(y, t, t_next, step, [](double err) { return std::cbrt(1.0 / err); });
}

// The stiff sample by RODAS4 (Hairer & Wanner 1996, Solving Ordinary Differential Equations II, sec. VI.4, the
// coefficients of their code RODAS in its transformed form): E = I / (gamma h) - J, gamma = 1/4, and for the
// autonomous system (the input is held in a sample)
//   E u_i = f(y + sum_j<i a_ij u_j) + sum_j<i (c_ij / h) u_j,  i = 1..6,
// where stages 5 and 6 are stiffly accurate: y + sum a_5j u_j + u_5 is the embedded third-order solution (the
// sixth stage's argument) and the fourth-order result adds u_6, which is the error estimate, weighed as dopri5's;
// the step follows err^(-1/4).  One Jacobian and one LU a step, six right-hand sides and six solves.
template <class System>
Status BasicDopri5Integrator<System>::rodas4_sample(const System& sys, const Input& in, State& y, double& t,
                                                    double t_next) noexcept {
  constexpr double kGamma = 0.25;
  constexpr double a21 = 1.544, a31 = 0.9466785280815826, a32 = 0.2557011698983284, a41 = 3.314825187068521,
                   a42 = 2.896124015972201, a43 = 0.9986419139977817, a51 = 1.221224509226641,
                   a52 = 6.019134481288629, a53 = 12.53708332932087, a54 = -0.6878860361058950;
  constexpr double c21 = -5.6688, c31 = -2.430093356833875, c32 = -0.2063599157091915, c41 = -0.1073529058151375,
                   c42 = -9.594562251023355, c43 = -20.47028614809616, c51 = 7.496443313967647,
                   c52 = -10.24680431464352, c53 = -33.99990352819905, c54 = 11.70890893206160,
                   c61 = 8.083246795921522, c62 = -7.981132988064893, c63 = -31.52159432874371,
                   c64 = 16.31930543123136, c65 = -6.058818238834054;
  State f{}, u1{}, u2{}, u3{}, u4{}, u5{}, u6{};
  double* W = W_.data();
  const auto step = [&](auto size, double h, State& yn, Status& st) {
    const int m = size;
    // E = I / (gamma h) - J: built as -(J) then the diagonal
    Sys::jacobian_rhs(sys, y.data(), in, W, f.data());
    for (int i = 0; i < m * m; ++i) W[i] = -W[i];
    for (int i = 0; i < m; ++i) W[i + i * m] += 1.0 / (kGamma * h);
    lu_factor(W, size, piv_.data());
    const double ih = 1.0 / h;
    for (int i = 0; i < m; ++i) u1[i] = f[i];
    lu_solve(W, size, piv_.data(), u1.data());
    for (int i = 0; i < m; ++i) yn[i] = y[i] + a21 * u1[i];
    Sys::rhs(sys, yn.data(), in, f.data());
    for (int i = 0; i < m; ++i) u2[i] = f[i] + ih * c21 * u1[i];
    lu_solve(W, size, piv_.data(), u2.data());
    for (int i = 0; i < m; ++i) yn[i] = y[i] + a31 * u1[i] + a32 * u2[i];
    Sys::rhs(sys, yn.data(), in, f.data());
    for (int i = 0; i < m; ++i) u3[i] = f[i] + ih * (c31 * u1[i] + c32 * u2[i]);
    lu_solve(W, size, piv_.data(), u3.data());
    for (int i = 0; i < m; ++i) yn[i] = y[i] + a41 * u1[i] + a42 * u2[i] + a43 * u3[i];
    Sys::rhs(sys, yn.data(), in, f.data());
    for (int i = 0; i < m; ++i) u4[i] = f[i] + ih * (c41 * u1[i] + c42 * u2[i] + c43 * u3[i]);
    lu_solve(W, size, piv_.data(), u4.data());
    for (int i = 0; i < m; ++i) yn[i] = y[i] + a51 * u1[i] + a52 * u2[i] + a53 * u3[i] + a54 * u4[i];
    Sys::rhs(sys, yn.data(), in, f.data());
    for (int i = 0; i < m; ++i) u5[i] = f[i] + ih * (c51 * u1[i] + c52 * u2[i] + c53 * u3[i] + c54 * u4[i]);
    lu_solve(W, size, piv_.data(), u5.data());
    for (int i = 0; i < m; ++i) yn[i] += u5[i];  // the embedded solution
    Sys::rhs(sys, yn.data(), in, f.data());
    for (int i = 0; i < m; ++i)
      u6[i] = f[i] + ih * (c61 * u1[i] + c62 * u2[i] + c63 * u3[i] + c64 * u4[i] + c65 * u5[i]);
    lu_solve(W, size, piv_.data(), u6.data());
    st.rhs_evals += 6;
    double sum = 0.0;
    for (int i = 0; i < m; ++i) {
      yn[i] += u6[i];
      const double sc = atol_[i] + rtol_ * std::max(std::fabs(y[i]), std::fabs(yn[i]));
      sum += (u6[i] / sc) * (u6[i] / sc);
    }
    return std::sqrt(sum / m);
  };
  return rosenbrock_steps(y, t, t_next, step, [](double err) { return std::pow(err, -0.25); });
}

template <class System>
Status BasicDopri5Integrator<System>::implicit_sample(const System& sys, const Input& in, State& y, double& t,
                                                      double t_next) noexcept {
  Status tried;
  if (rosenbrock_ && !rosenbrock_failed_) {
    const State y0 = y;
    const double t0 = t;
    tried = rosenbrock_order_ == 4 ? rodas4_sample(sys, in, y, t, t_next) : rosenbrock_sample(sys, in, y, t, t_next);
    if (tried.ok()) return tried;
    y = y0;  // more than kRosenbrockAttempts steps (an accuracy-bound sample at a tight tolerance): CVODE's BDF
    t = t0;
    --stiff_samples_;
    rosenbrock_failed_ = true;  // the rest of this stretch of stiff samples goes to CVODE directly
  }
  implicit_->reset(y, t);
  Status st = implicit_->advance(sys, in, y, t, t_next);
  st.internal_steps += tried.internal_steps;
  st.rhs_evals += tried.rhs_evals;
  ++restarts_;
  fsal_ = false;
  h_ = dt_;
  st.stiff = true;
  ++stiff_samples_;
  return st;
}

template <class System>
Status BasicDopri5Integrator<System>::advance(const System& sys, const Input& in, State& y, double& t,
                                              double t_next) noexcept {
  Status st;
  const State y0 = y;
  const double t0 = t;
  if (hold_ > 0 && implicit_) {
    --hold_;
    st = implicit_sample(sys, in, y, t, t_next);
  } else {
    rosenbrock_failed_ = false;
    const Outcome out = explicit_sample(sys, in, y, t, t_next, st);
    if (out != Outcome::Done) {
      y = y0;
      t = t0;
      if (out == Outcome::Stiff && implicit_) {
        const Status tried = st;
        st = implicit_sample(sys, in, y, t, t_next);
        st.internal_steps += tried.internal_steps;  // the explicit attempt's work counts too
        st.rhs_evals += tried.rhs_evals;
        hold_ = kImplicitHold;
      } else {
        st.code = out == Outcome::Stiff ? Status::Stiff : Status::TooMuchWork;
        fsal_ = false;
        h_ = dt_;
      }
    }
  }
  if (shadow_ && st.ok()) {
    if (shadow_live_ || st.stiff)
      verify(sys, in, y0, t0, y, t_next, st);  // from the first stiff sample to the end of the run
    else
      gap_.track(sys, in, y);
  }
  steps_done_ += st.internal_steps;
  rhs_done_ += st.rhs_evals;
  st.t = t;
  return st;
}

template class BasicDopri5Integrator<Dynamics>;
template class BasicDopri5Integrator<MultiRig>;

}  // namespace servohydraulics::detail
