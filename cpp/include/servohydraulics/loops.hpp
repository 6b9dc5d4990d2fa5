// The paper's two real-time test methods as simulated closed loops stepped at
// the controller rate (Zhao et al. 2003, Figs 1 and 7): a controller of
// controllers.hpp composed with the simulated Plant.  Construct once
// (validates, throws Error, allocates); reset() and step() are noexcept and
// allocation-free, step() returns the plant's Status.
//
// Row convention (as record.hpp): step() fills row k with the sensors at t_k,
// then the controller computes from them the command it holds over
// [t_k, t_k + dt], then the plant advances to t_{k+1}.  Optional sensor and
// converter blocks (loop_converters.hpp; all off by default) sit between the
// plant and the controller: the controller then sees the measured channels and
// the plant receives the converted command; the row keeps the plant's true
// sensors and the controller's own channels (its command before the D/A).  A laboratory runs the
// same controller on its own rig, with its I/O in place of the Plant
// (examples/02_rpsd_controller.cpp).
#pragma once

#include <cstddef>
#include <optional>
#include <utility>

#include "servohydraulics/config_fields.hpp"
#include "servohydraulics/controllers.hpp"
#include "servohydraulics/loop_converters.hpp"
#include "servohydraulics/plant.hpp"
#include "servohydraulics/record.hpp"

namespace servohydraulics {

//! A controller in closed loop with the simulated plant: sensors at t_k ->
//! controller.command(sensors, inputs..., &row) -> plant.step(command).
template <class Controller>
class ClosedLoop {
 public:
  ClosedLoop(Plant plant, Controller controller, const LoopConverters& converters = {})
      : plant_(std::move(plant)), controller_(std::move(controller)), io_(converters) {
    reset();
  }

  void reset() noexcept {  //!< plant, controller and converter blocks at rest at t = 0
    plant_.reset(0.0, 0.0);
    plant_.observe(last_);
    controller_.reset();
    io_.reset();
  }
  //! Row k: the sensors at t_k and what the controller computed from them (Row
  //! is EftOutput or RpsdOutput); inputs are the controller's exogenous inputs.
  template <class Row, class... Inputs>
  Status step(Row& row, Inputs... inputs) noexcept {
    if (!io_.active()) {
      const double u = controller_.command(last_, inputs..., &row);
      return plant_.step(u, last_);
    }
    io_.measure(last_, measured_);
    const double u = io_.actuate(controller_.command(measured_, inputs..., &row));
    row.plant = last_;
    return plant_.step(u, last_);
  }

  const Plant& plant() const noexcept { return plant_; }
  const Controller& controller() const noexcept { return controller_; }
  const Output& sensors() const noexcept { return last_; }  //!< the plant's output at the current time
  const LoopIo& converters() const noexcept { return io_; }

 protected:
  Plant plant_;
  Controller controller_;
  LoopIo io_;
  Output last_, measured_;
};

// ---------------------------------------------------------------------------
// The simulated loops' own settings: how the plant is simulated.  Not the
// controller's (a laboratory's controller config, controllers.hpp, has none of
// them); each has its field table like the configs (the binding's attributes,
// _core.EFT_LOOP_OPTION_FIELDS / RPSD_LOOP_OPTION_FIELDS, sh.run_eft / run_rpsd's keywords).
// ---------------------------------------------------------------------------

struct EftLoopOptions {
  SolverOptions plant_options;  //!< the simulated plant's ODE integrator
  void validate() const { plant_options.validate(); }
};
inline constexpr auto kEftLoopOptionFields = std::make_tuple(
    config_field("plant_options", "", "the simulated plant's ODE integrator", &EftLoopOptions::plant_options));

struct RpsdLoopOptions {
  SolverOptions plant_options;          //!< the simulated plant's ODE integrator
  double physical_mass_fraction = 1.0;  //!< the plant's structural mass = fraction * m_m (substructuring)
  void validate() const;
};
inline constexpr auto kRpsdLoopOptionFields = std::make_tuple(
    config_field("plant_options", "", "the simulated plant's ODE integrator", &RpsdLoopOptions::plant_options),
    config_field("physical_mass_fraction", "-", "the plant's structural mass / m_m",
                 &RpsdLoopOptions::physical_mass_fraction));

// ---------------------------------------------------------------------------
// Effective force testing (force control, Fig 1a)
// ---------------------------------------------------------------------------

class EffectiveForceTest : public ClosedLoop<EftController> {
 public:
  //! rig: the plant; model: the controller's model of the rig for the compensator
  //! (none = the same rig, i.e. perfect knowledge).  config.mass none = rig.m
  //! (the plant's, whatever the model).
  //! converters: the optional sensor and converter blocks (loop_converters.hpp; off by default).
  //! tracking: as EftController's (not owned; nullptr = the paper's velocity feedback compensation).
  //! options: how the plant is simulated (its ODE integrator).
  EffectiveForceTest(const Rig& rig, const EftConfig& config, const std::optional<Rig>& model = std::nullopt,
                     const LoopConverters& converters = {}, TrackingController* tracking = nullptr,
                     const EftLoopOptions& options = {});

  Status step(double ground_acceleration, EftOutput& out) noexcept {
    return ClosedLoop::step(out, ground_acceleration);
  }

  const EftConfig& config() const noexcept { return controller_.config(); }
  const VelocityFeedbackCompensator& compensator() const noexcept { return controller_.compensator(); }
};

// ---------------------------------------------------------------------------
// Real-time pseudodynamic testing (displacement control, Figs 1b, 7)
// ---------------------------------------------------------------------------

class RealTimePseudoDynamicTest : public ClosedLoop<RpsdController> {
 public:
  //! rig: the physical test (its m is replaced by options.physical_mass_fraction * m_m).
  //! converters: the optional sensor and converter blocks (loop_converters.hpp; off by default).
  //! tracking, substructure: as RpsdController's (not owned; nullptr = the paper's).
  //! options: how the plant is simulated (its ODE integrator, its mass).
  RealTimePseudoDynamicTest(const Rig& rig, const RpsdConfig& config, const LoopConverters& converters = {},
                            TrackingController* tracking = nullptr, NumericalSubstructure* substructure = nullptr,
                            const RpsdLoopOptions& options = {});

  //! ground_acceleration [m/s^2], external_force into the solver [N], restoring_force_error added to f [N].
  Status step(double ground_acceleration, double external_force, double restoring_force_error,
              RpsdOutput& out) noexcept {
    return ClosedLoop::step(out, ground_acceleration, external_force, restoring_force_error);
  }

  //! The rig the plant simulates: rig with m = options.physical_mass_fraction * config.model.m_m (validated).
  static Rig physical_rig(const Rig& rig, const RpsdConfig& config, const RpsdLoopOptions& options = {});

  const RpsdConfig& config() const noexcept { return controller_.config(); }
  const IntegratorState& integrator_state() const noexcept { return controller_.integrator_state(); }
  double k_m() const noexcept { return controller_.k_m(); }
  double subtract_mass() const noexcept { return controller_.subtract_mass(); }
  double subtract_damping() const noexcept { return controller_.subtract_damping(); }
};

// ---------------------------------------------------------------------------
// Whole-record runners: n samples, rows written to a caller-provided buffer of
// n rows (no allocation, no throw); stop at the first failed sample (its row is
// written; summary.rows counts the rows written).
// ---------------------------------------------------------------------------

RunSummary run_eft(EffectiveForceTest& test, const double* ground_acceleration, std::size_t n,
                   EftOutput* rows) noexcept;
//! external_force and restoring_force_error may be nullptr (zero).
RunSummary run_rpsd(RealTimePseudoDynamicTest& test, const double* ground_acceleration,
                    const double* external_force, const double* restoring_force_error, std::size_t n,
                    RpsdOutput* rows) noexcept;

}  // namespace servohydraulics
