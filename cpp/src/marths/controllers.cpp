#include "servohydraulics/marths/controllers.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "servohydraulics/error.hpp"

namespace servohydraulics::marths {

// ------------------------------------------------------------------------------------------- RoDeAC

void RodeacConfig::validate() const {
  require(!channels.empty() && channels.size() <= 8, "rodeac.channels", static_cast<double>(channels.size()),
          "1 to 8 actuators");
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const RodeacChannel& c = channels[i];
    const std::string th = "rodeac.theta0[" + std::to_string(i) + "]", P = "rodeac.P0[" + std::to_string(i) + "]";
    const Eigen::Index n = c.theta0.size();
    require(n >= 1 && n <= kMaxTaps, th.c_str(), static_cast<double>(n), "1 to 8 FIR taps");
    require(c.theta0.allFinite(), th.c_str(), c.theta0.sum(), "finite");
    require(c.P0.rows() == n && c.P0.cols() == n, P.c_str(), static_cast<double>(c.P0.rows()),
            "square, one row per tap of theta0");
    require(c.P0.allFinite(), P.c_str(), c.P0.sum(), "finite");
    const double peak = c.P0.cwiseAbs().maxCoeff();
    require((c.P0 - c.P0.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * peak, P.c_str(), c.P0(0, n - 1),
            "symmetric");
    if (peak > 0.0) {
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (c.P0 + c.P0.transpose()), Eigen::EigenvaluesOnly);
      require(es.eigenvalues().minCoeff() >= -1e-12 * peak, P.c_str(), es.eigenvalues().minCoeff(),
              "positive semi-definite (an inverse correlation matrix): its smallest eigenvalue");
    }
  }
  require(std::isfinite(forgetting) && forgetting > 0.0 && forgetting <= 1.0, "rodeac.forgetting", forgetting,
          "in (0, 1]");
  filter.validate();
  require(std::isfinite(unit) && unit > 0.0, "rodeac.unit", unit, "finite and > 0 [m]");
}

RodeacController::RodeacController(const RodeacConfig& config) : cfg_(config) {
  cfg_.validate();
  ch_.resize(cfg_.channels.size());
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    const Eigen::Index n = cfg_.channels[i].theta0.size();
    Channel& c = ch_[i];
    for (TapVector* v : {&c.theta, &c.X, &c.T, &c.PX, &c.XtP, &c.phi}) v->setZero(n);
    c.P.setZero(n, n);
    c.fx = IirFilter(cfg_.filter);
    c.fu = IirFilter(cfg_.filter);
  }
  reset();
}

void RodeacController::reset() noexcept {
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    Channel& c = ch_[i];
    c.theta = cfg_.channels[i].theta0;
    c.P = cfg_.channels[i].P0;
    c.X.setZero();
    c.T.setZero();
    c.fx.reset();
    c.fu.reset();
  }
}

void RodeacController::command(const MultiTrackingInput& in, double* u) noexcept {
  const double scale = 1.0 / cfg_.unit, lambda = cfg_.forgetting;
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    Channel& c = ch_[i];
    const Eigen::Index n = c.theta.size();
    // the taps: X = [xf_k .. xf_{k-n+1}], T = [target_k .. target_{k-n+1}] (in the model's unit)
    for (Eigen::Index j = n - 1; j > 0; --j) {
      c.X(j) = c.X(j - 1);
      c.T(j) = c.T(j - 1);
    }
    c.X(0) = c.fx.step(scale * in.measured[i]);
    c.T(0) = scale * in.desired[i];
    // RLS (the RLS-AC blocks): phi = P X / (lambda + X^T P X); P+ = (P - phi X^T P) / lambda;
    // theta+ = theta + phi (uf_k - theta^T X) with uf_k = B(z) u_k of this same sample.
    c.PX.noalias() = c.P * c.X;
    c.phi = c.PX / (lambda + c.X.dot(c.PX));
    // u_k = theta+^T T: linear in u_k through uf_k = b0 u_k + pending, so
    // u_k = [theta^T T + (phi^T T)(pending - theta^T X)] / (1 - b0 phi^T T).
    const double g = c.phi.dot(c.T), thX = c.theta.dot(c.X);
    const double den = 1.0 - c.fu.feedthrough() * g;
    const double uk = den != 0.0 ? (c.theta.dot(c.T) + g * (c.fu.pending() - thX)) / den
                                 : std::numeric_limits<double>::quiet_NaN();
    const double uf = c.fu.step(uk);
    c.theta += c.phi * (uf - thX);
    // X^T P: the model's row vector (P stays symmetric only to round-off)
    c.XtP.noalias() = c.P.transpose() * c.X;
    for (Eigen::Index r = 0; r < n; ++r)
      for (Eigen::Index s = 0; s < n; ++s) c.P(r, s) = (c.P(r, s) - c.phi(r) * c.XtP(s)) / lambda;
    u[i] = uk * cfg_.unit;
  }
}

// ------------------------------------------------------------------------------------------- PassThrough, decentralized

PassThrough::PassThrough(std::size_t actuators) : n_(actuators) {
  require(actuators >= 1 && actuators <= 8, "actuators", static_cast<double>(actuators), "1 to 8");
}

DecentralizedController::DecentralizedController(std::vector<TrackingController*> channels, double dt)
    : ch_(std::move(channels)), dt_(dt) {
  require(!ch_.empty() && ch_.size() <= 8, "decentralized.channels", static_cast<double>(ch_.size()), "1 to 8");
  require(std::isfinite(dt) && dt >= 0.0, "decentralized.dt", dt, "finite and >= 0 [s] (0: the loop's rates)");
  const double h = dt > 0.0 ? dt : 1.0;
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    dv_.emplace_back(h);
    da_.emplace_back(h);
  }
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    const std::string f = "decentralized.channels[" + std::to_string(i) + "]";
    require(ch_[i] != nullptr, f.c_str(), 0.0, "a tracking controller (not null)");
  }
}

void DecentralizedController::reset() noexcept {
  for (TrackingController* c : ch_) c->reset();
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    dv_[i].reset();
    da_[i].reset();
  }
}

void DecentralizedController::command(const MultiTrackingInput& in, double* u) noexcept {
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    TrackingInput t;
    t.desired = in.desired[i];
    if (dt_ > 0.0) {
      t.desired_velocity = dv_[i](in.desired[i]);
      t.desired_acceleration = da_[i](t.desired_velocity);
    } else {
      t.desired_velocity = in.desired_velocity ? in.desired_velocity[i] : 0.0;
      t.desired_acceleration = in.desired_acceleration ? in.desired_acceleration[i] : 0.0;
    }
    t.measured = in.measured[i];
    u[i] = ch_[i]->command(t);
  }
}

// ------------------------------------------------------------------------------------------- MIMO feedforward

void MimoFeedforwardConfig::validate() const {
  require(std::isfinite(dt) && dt > 0.0, "dt", dt, "finite and > 0 [s]");
  require(!coefficients.empty() && coefficients.size() <= 4, "feedforward.order",
          static_cast<double>(coefficients.size()) - 1.0, "0 to 3");
  const Eigen::Index n = coefficients[0].rows();
  require(n >= 1 && n <= 8, "feedforward.actuators", static_cast<double>(n), "1 to 8");
  for (std::size_t m = 0; m < coefficients.size(); ++m) {
    const std::string f = "feedforward.coefficients[" + std::to_string(m) + "]";
    require(coefficients[m].rows() == n && coefficients[m].cols() == n, f.c_str(),
            static_cast<double>(coefficients[m].rows()), "N x N");
    require(coefficients[m].allFinite(), f.c_str(), coefficients[m].sum(), "finite");
  }
  pi.validate();
}

MimoFeedforwardConfig MimoFeedforwardConfig::from_plant(const StateSpace& plant, int order, double dt) {
  require(order >= 0 && order <= 3, "feedforward.order", order, "0 to 3");
  require(plant.inputs() == plant.outputs(), "plant.inputs", static_cast<double>(plant.inputs()),
          "the number of outputs");
  const std::vector<Eigen::MatrixXd> H = plant.taylor_coefficients(order);
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(H[0]);
  require(lu.isInvertible(), "plant.dc_gain", H[0].determinant(), "an invertible DC gain matrix H(0)");
  MimoFeedforwardConfig c;
  c.dt = dt;
  for (int m = 0; m <= order; ++m) {
    Eigen::MatrixXd acc = Eigen::MatrixXd::Zero(H[0].rows(), H[0].rows());
    if (m == 0) acc.setIdentity();
    for (int j = 1; j <= m; ++j) acc -= H[static_cast<std::size_t>(j)] * c.coefficients[static_cast<std::size_t>(m - j)];
    c.coefficients.push_back(lu.solve(acc));
  }
  c.validate();
  return c;
}

MimoFeedforward::MimoFeedforward(const MimoFeedforwardConfig& config) : cfg_(config) {
  cfg_.validate();
  const std::size_t n = actuators();
  for (std::size_t i = 0; i < n; ++i) {
    dr_.emplace_back(cfg_.dt);
    ddr_.emplace_back(cfg_.dt);
    dddr_.emplace_back(cfg_.dt);
    pi_.emplace_back(cfg_.pi.Kp, cfg_.pi.Ki, 1.0, 0.0, cfg_.dt);
  }
  deriv_.setZero(static_cast<Eigen::Index>(n), 4);
  out_.setZero(static_cast<Eigen::Index>(n));
  reset();
}

void MimoFeedforward::reset() noexcept {
  for (std::size_t i = 0; i < dr_.size(); ++i) {
    dr_[i].reset();
    ddr_[i].reset();
    dddr_[i].reset();
    pi_[i].reset();
  }
}

void MimoFeedforward::command(const MultiTrackingInput& in, double* u) noexcept {
  const std::size_t n = actuators();
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    deriv_(r, 0) = in.desired[i];
    deriv_(r, 1) = dr_[i](deriv_(r, 0));
    deriv_(r, 2) = ddr_[i](deriv_(r, 1));
    deriv_(r, 3) = dddr_[i](deriv_(r, 2));
  }
  out_.setZero();
  for (std::size_t m = 0; m < cfg_.coefficients.size(); ++m)
    out_.noalias() += cfg_.coefficients[m] * deriv_.col(static_cast<Eigen::Index>(m));
  for (std::size_t i = 0; i < n; ++i) u[i] = out_(static_cast<Eigen::Index>(i)) + pi_[i](in.desired[i] - in.measured[i]);
}

}  // namespace servohydraulics::marths
