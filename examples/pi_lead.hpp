// PiLead: the benchmark's PI + phase lead written out as a user's C++ tracking
// controller (examples/07_user_controller.cpp runs it in the RTHS loop;
// examples/07_user_controller_module.cpp exposes it to Python).  It derives the core's
// interface, rths::TrackingController: reset() and command(const TrackingInput&), both
// noexcept and allocation-free.
#pragma once

#include "servohydraulics/rths/tracking.hpp"

namespace rths = servohydraulics::rths;

//! PI on the tracking error + phase lead on the reference, with the benchmark's 18-bit converters.
class PiLead final : public rths::TrackingController {
 public:
  explicit PiLead(double dt = 1.0 / 4096.0, double Kp = 2.0, double Ki = 95.0, double lead_b1 = 50.83163360273612,
                  double lead_b0 = 8570.397339444286, double lead_a0 = 8570.397339444286)
      : lead_(tustin(lead_b1, lead_b0, 1.0, lead_a0, dt)), pi_(tustin(Kp, Ki, 1.0, 0.0, dt)) {}

  void reset() noexcept override { r1_ = yl1_ = e1_ = yc1_ = 0.0; }

  double command(const rths::TrackingInput& in) noexcept override {
    const double r = ad_(in.desired);
    const double yl = -lead_.d1 * yl1_ + lead_.n0 * r + lead_.n1 * r1_;  // phase lead on the reference
    r1_ = r;
    yl1_ = yl;
    const double e = ad_(da_(yl) - in.measured);  // tracking error
    const double yc = -pi_.d1 * yc1_ + pi_.n0 * e + pi_.n1 * e1_;  // PI
    e1_ = e;
    yc1_ = yc;
    return da_(yc);
  }

 private:
  struct Coefficients {
    double n0, n1, d1;
  };
  //! (b1 s + b0) / (a1 s + a0) by Tustin at h: y_k = -d1 y_k-1 + n0 u_k + n1 u_k-1.
  static Coefficients tustin(double b1, double b0, double a1, double a0, double h) {
    const double c = 2.0 / h, D = a1 * c + a0;
    return {(b1 * c + b0) / D, (b0 - b1 * c) / D, (a0 - a1 * c) / D};
  }
  Coefficients lead_, pi_;
  rths::Converter ad_ = rths::benchmark_converter(rths::Converter::Kind::AnalogToDigital);
  rths::Converter da_ = rths::benchmark_converter(rths::Converter::Kind::DigitalToAnalog);
  double r1_ = 0.0, yl1_ = 0.0, e1_ = 0.0, yc1_ = 0.0;
};
