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
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <tuple>
#include <type_traits>

#include "servohydraulics/elements/bouc_wen.hpp"
#include "servohydraulics/elements/fluid_damper.hpp"
#include "servohydraulics/elements/mr_damper.hpp"
#include "servohydraulics/elements/pade_delay.hpp"

namespace servohydraulics {

//! Every switchable element, in the order their states are appended.
using Elements = std::tuple<BoucWen, MrDamper, PadeDelay, FluidDamper>;

constexpr std::size_t kNumElements = std::tuple_size_v<Elements>;

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
