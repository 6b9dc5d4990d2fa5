// One FMU instance: the settings read from resources/, the values of its
// variables, and the plant or controller they drive.  No global state: any
// number of instances run side by side in one process.
//
// Timing (the row convention of record.hpp and loops.hpp):
// - plant: the command set at t_k is held over [t_k, t_k + h]; after doStep the
//   outputs are the plant's channels at t_k + h (no direct feedthrough).
// - controllers: a discrete-time system with direct feedthrough.  Its outputs
//   at t_k are what the controller computes from the inputs set at t_k (the
//   sensors at t_k and a_g(t_k)); doStep(t_k, h) commits that sample and runs
//   the remaining h / dt - 1 samples on the same (held) inputs.  Reading an
//   output computes the sample on a copy of the controller, so reading twice
//   or not at all changes nothing; doStep commits the copy.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "model.hpp"

namespace servohydraulics::fmu {

class Instance {
 public:
  //! Reads resource_dir (fmu.toml, rig.toml); throws Error naming the cause,
  //! also when guid differs from the exporter's.
  Instance(const std::string& resource_dir, const std::string& guid);

  const std::vector<Variable>& variables() const noexcept { return vars_; }
  Kind kind() const noexcept { return values_.settings.kind; }

  //! Back to the settings of the resources (fmi2Reset).
  void reset();
  //! Builds the plant or controller from the current parameters at start_time
  //! (fmi2ExitInitializationMode); throws Error naming the bad parameter.
  void initialize(double start_time);

  //! The value of variable vr (controllers: computes the sample if an input changed).
  double get(std::size_t vr) noexcept;
  //! Sets variable vr; throws Error naming it and the value when the value is
  //! invalid or the variable cannot be set now (a fixed parameter after
  //! initialisation, an output).  A tunable parameter rebuilds the plant at
  //! its current state.
  void set(std::size_t vr, double value);

  //! Advances from t by h, a whole number of controller samples.  Returns an
  //! empty string, or what went wrong (wrong t or h, solver failure and its time).
  std::string do_step(double t, double h) noexcept;

  double time() const noexcept { return t_start_ + static_cast<double>(k_) * values_.settings.dt; }
  bool initialized() const noexcept { return initialized_; }
  bool failed() const noexcept { return failed_; }  //!< the plant failed: only reset() helps

 private:
  //! A controller and its trial copy: outputs are computed on the copy,
  //! doStep commits it (swaps the roles).  Copy-assignment reuses the buffers.
  template <class C>
  struct Slot {
    std::array<std::optional<C>, 2> c;
    int cur = 0;
    bool trial_valid = false;
  };
  template <class C>
  void build(Slot<C>& slot, const C& controller);
  template <class C>
  void evaluate(Slot<C>& slot) noexcept;
  template <class C>
  void advance(Slot<C>& slot, long samples) noexcept;
  void invalidate_trial() noexcept;
  void rebuild_plant();
  std::string step_plant(long samples) noexcept;

  Settings initial_;
  Values values_;
  std::vector<Variable> vars_;
  std::optional<Plant> plant_;
  Slot<EftController> eft_;
  Slot<RpsdController> rpsd_;
  double t_start_ = 0.0;
  long k_ = 0;  // samples since t_start_
  bool initialized_ = false;
  bool failed_ = false;
};

}  // namespace servohydraulics::fmu
