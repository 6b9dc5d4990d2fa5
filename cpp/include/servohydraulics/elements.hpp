// The plant's physical elements, one small type each, folded over by Dynamics (as
// pinocchio's joint collection is the model).  An element is a struct with
//   kName (its Effects switch), kPort (Structure or Drive), kCapacity (most states),
//   static std::optional<E> from(const Rig&, ControlMode)   (nullopt: off),
//   int count()                   its states (appended after the base states, in tuple order),
//   static const StateInfo* states()                 their names, units and meanings,
//   double scale(int k)           the magnitude of its state k (the unit of its tolerance),
//   void rest(const RestPoint&, double* z)           its states at rest,
//   double static_force(double x) its force at rest at x (Structure),
//   double rate_bound(double v_ref)                  |d rate / d state| when sliding at v_ref,
//   template <int W> void eval(const double* y, int offset, Algebra&)
//                                 adds its force (or delays the drive) and writes its states'
//                                 rates, with their gradients (the first W columns),
//   void jacobian(const Algebra&, int offset, int n, int ku, Jacobian&, State* B)
//                                 its rows of J and B (copy_rows, or constant rows of its own).
// Adding an element: docs/architecture.md, "Add an element".
//
// The structure's own laws of Eq (5), the spring with its softening, the viscous damping and the
// friction laws (the static law, LuGre), are a second, smaller collection, StructureLaws, folded
// the same way, because they differ from the switchable elements in three ways: they are the
// structure, not a specimen (their force is not the specimen_force channel nor the kinematic
// driver's); they append no state (LuGre's bristle is the base state kZ, so that the layout, the
// channels and the FMU's variables stay the paper plant's); and they are functions of x, v and z
// only, so each returns a LawForce (its force and three partial derivatives) rather than rows of
// the full gradient width.  A law is a struct with
//   kName, static std::optional<L> from(const Rig&, ControlMode) (nullopt: off; the spring and
//   the damping are always on), double static_force(double x) (kNoStaticForce when it holds
//   nothing at rest), double rate_bound(double v_ref) (its state's stiffness, for the RK4 rule),
//   LawForce eval(const double* y, Algebra&) (LuGre also writes the bristle's rate zdot, dzdot).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <tuple>
#include <type_traits>

#include "servohydraulics/elements/bouc_wen.hpp"
#include "servohydraulics/elements/fluid_damper.hpp"
#include "servohydraulics/elements/friction.hpp"
#include "servohydraulics/elements/mr_damper.hpp"
#include "servohydraulics/elements/pade_delay.hpp"
#include "servohydraulics/elements/spring.hpp"
#include "servohydraulics/elements/viscous_damping.hpp"

namespace servohydraulics {

//! Every switchable element, in the order their states are appended.
using Elements = std::tuple<BoucWen, MrDamper, PadeDelay, FluidDamper>;

constexpr std::size_t kNumElements = std::tuple_size_v<Elements>;

//! The structure's laws, in the order Eq (5) subtracts their forces (pA - F_f - c v - f_s(x)):
//! at most one friction law is on, the damping and the spring always are.
using StructureLaws = std::tuple<TanhFriction, LuGreFriction, ViscousDamping, Spring>;

namespace detail {
template <class T, class Tuple>
struct IndexOf;
template <class T, class... E>
struct IndexOf<T, std::tuple<T, E...>> : std::integral_constant<std::size_t, 0> {};
template <class T, class U, class... E>
struct IndexOf<T, std::tuple<U, E...>> : std::integral_constant<std::size_t, 1 + IndexOf<T, std::tuple<E...>>::value> {};
template <class Tuple>
struct Optionals;
template <class... E>
struct Optionals<std::tuple<E...>> {
  using type = std::tuple<std::optional<E>...>;
  static constexpr int capacity = (0 + ... + E::kCapacity);
  static constexpr std::array<const char*, sizeof...(E)> names{E::kName...};
};
}  // namespace detail

//! Index of element E in Elements.
template <class E>
constexpr std::size_t element_index = detail::IndexOf<E, Elements>::value;
//! The elements' names (their Effects switches), in tuple order.
constexpr std::array<const char*, kNumElements> kElementNames = detail::Optionals<Elements>::names;

static_assert(kNumStates + detail::Optionals<Elements>::capacity <= kMaxStates,
              "kMaxStates too small for every element switched on");

//! Where the switched-on elements' states sit in the state vector (offset -1: element off).
struct StateLayout {
  int num_states = kNumStates;           //!< active count
  std::array<int, kNumElements> offset;  //!< first state of each element (tuple order)
  std::array<int, kNumElements> count;   //!< how many states it has
  StateLayout() noexcept {
    offset.fill(-1);
    count.fill(0);
  }
  template <class E>
  int offset_of() const noexcept { return offset[element_index<E>]; }
  template <class E>
  int count_of() const noexcept { return count[element_index<E>]; }
};

}  // namespace servohydraulics
