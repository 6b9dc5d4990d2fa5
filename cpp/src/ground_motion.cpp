#include "servohydraulics/ground_motion.hpp"

#include <cmath>

#include "servohydraulics/error.hpp"

namespace servohydraulics {

GroundMotion::GroundMotion(std::vector<double> time, std::vector<double> acceleration, double scale)
    : t_(std::move(time)), a_(std::move(acceleration)), scale_(scale) {
  require(t_.size() >= 2, "time.size", static_cast<double>(t_.size()), ">= 2 samples");
  require(a_.size() == t_.size(), "acceleration.size", static_cast<double>(a_.size()), "the size of time");
  require(std::isfinite(scale), "scale", scale, "finite");
  for (std::size_t i = 0; i < t_.size(); ++i) {
    require(std::isfinite(t_[i]) && std::isfinite(a_[i]), "record", static_cast<double>(i), "finite samples");
    if (i > 0) require(t_[i] > t_[i - 1], "time", t_[i], "strictly increasing");
  }
}

double GroundMotion::operator()(double t) const noexcept {
  if (t <= t_.front()) return scale_ * a_.front();
  if (t >= t_.back()) return scale_ * a_.back();
  if (t < t_[cursor_]) cursor_ = 0;  // backwards query: restart
  while (t_[cursor_ + 1] < t) ++cursor_;
  const std::size_t i = cursor_;
  const double w = (t - t_[i]) / (t_[i + 1] - t_[i]);
  return scale_ * (a_[i] + w * (a_[i + 1] - a_[i]));
}

}  // namespace servohydraulics
