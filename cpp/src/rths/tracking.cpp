#include "servohydraulics/rths/tracking.hpp"

#include "servohydraulics/error.hpp"

namespace servohydraulics::rths {

ModelBasedConfig model_based_config(const BenchmarkPlantParameters& plant, int order) {
  plant.validate();
  return ModelBasedConfig::from_denominator(plant.denominator(), plant.numerator(), order);
}

double plant_delay(const BenchmarkPlantParameters& plant) noexcept {
  const std::array<double, 6> A = plant.denominator();
  return A[4] / A[5];
}

}  // namespace servohydraulics::rths
