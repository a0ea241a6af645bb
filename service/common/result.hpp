#pragma once
// A small result type for layer boundaries: a value or an error enum, never an
// exception in the data path. Shaped like std::expected (C++23) so it can be
// swapped for it later.

#include <optional>
#include <type_traits>
#include <utility>
#include <variant>

namespace dh3 {

template <typename E>
struct Failure {
  E error;
};

/// Marks an error for returning through a Result: `return dh3::fail(BusError::link_down);`
template <typename E>
[[nodiscard]] constexpr Failure<E> fail(E error) {
  return Failure<E>{error};
}

template <typename T, typename E>
class [[nodiscard]] Result {
 public:
  constexpr Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}  // NOLINT
  constexpr Result(Failure<E> failure)                                             // NOLINT
      : state_(std::in_place_index<1>, failure.error) {}

  [[nodiscard]] constexpr bool ok() const { return state_.index() == 0; }
  constexpr explicit operator bool() const { return ok(); }

  constexpr T& value() & { return std::get<0>(state_); }
  constexpr const T& value() const& { return std::get<0>(state_); }
  constexpr T&& value() && { return std::get<0>(std::move(state_)); }
  constexpr T value_or(T fallback) const { return ok() ? std::get<0>(state_) : fallback; }
  constexpr E error() const { return std::get<1>(state_); }

  constexpr T* operator->() { return &value(); }
  constexpr const T* operator->() const { return &value(); }
  constexpr T& operator*() & { return value(); }
  constexpr const T& operator*() const& { return value(); }

 private:
  std::variant<T, E> state_;
};

template <typename E>
class [[nodiscard]] Result<void, E> {
 public:
  constexpr Result() = default;
  constexpr Result(Failure<E> failure) : error_(failure.error) {}  // NOLINT

  [[nodiscard]] constexpr bool ok() const { return !error_.has_value(); }
  constexpr explicit operator bool() const { return ok(); }
  constexpr E error() const { return *error_; }

 private:
  std::optional<E> error_;
};

}  // namespace dh3
