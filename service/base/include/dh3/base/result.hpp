#pragma once
// A small result type for layer boundaries: a value or an error, never an
// exception in the data path. Shaped like std::expected (C++23) so it can be
// swapped for it later.
//
// Every fallible function in the service returns one: E is an error enum where
// callers branch on the kind, a message (std::string or a struct) where they
// only report it. Asking a Result for what it does not hold (value() of an
// error, error() of a value) is a broken precondition, not a recoverable
// error: it ends the program with a message, in every build type.

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>

namespace dh3 {

/// The arguments of an error on its way into a Result; made by fail().
template <typename... Args>
struct Failure {
  std::tuple<Args...> args;
};

/// Marks an error for returning through a Result, whose error type is built
/// from the arguments in place: `return dh3::fail(BusError::link_down);`,
/// `return dh3::fail("no such file");` (E = std::string),
/// `return dh3::fail(ConfigError{path, message});`.
template <typename... Args>
[[nodiscard]] constexpr Failure<std::decay_t<Args>...> fail(Args&&... args) {
  return Failure<std::decay_t<Args>...>{{std::forward<Args>(args)...}};
}

namespace detail {

[[noreturn]] inline void result_misused(const char* what) {
  std::fprintf(stderr, "dh3::Result: %s\n", what);
  std::abort();
}

template <typename E, typename... Args>
constexpr E make_error(Failure<Args...>&& failure) {
  return std::apply([](auto&&... args) { return E(std::forward<decltype(args)>(args)...); },
                    std::move(failure.args));
}

}  // namespace detail

template <typename T, typename E>
class [[nodiscard]] Result {
 public:
  using value_type = T;
  using error_type = E;

  constexpr Result(T value)  // NOLINT(google-explicit-constructor): `return value;`
      : state_(std::in_place_index<0>, std::move(value)) {}
  template <typename... Args, typename = std::enable_if_t<std::is_constructible_v<E, Args&&...>>>
  constexpr Result(Failure<Args...> failure)  // NOLINT(google-explicit-constructor)
      : state_(std::in_place_index<1>, detail::make_error<E>(std::move(failure))) {}

  [[nodiscard]] constexpr bool ok() const { return state_.index() == 0; }
  [[nodiscard]] constexpr bool has_value() const { return ok(); }
  constexpr explicit operator bool() const { return ok(); }

  /// Precondition: ok().
  constexpr T& value() & { return *checked_value(); }
  constexpr const T& value() const& { return *checked_value(); }
  constexpr T&& value() && { return std::move(*checked_value()); }
  template <typename U>
  constexpr T value_or(U&& fallback) const& {
    return ok() ? *std::get_if<0>(&state_) : static_cast<T>(std::forward<U>(fallback));
  }
  template <typename U>
  constexpr T value_or(U&& fallback) && {
    return ok() ? std::move(*std::get_if<0>(&state_)) : static_cast<T>(std::forward<U>(fallback));
  }

  /// Precondition: !ok().
  constexpr const E& error() const& { return *checked_error(); }
  constexpr E& error() & { return *checked_error(); }
  constexpr E error() && { return std::move(*checked_error()); }

  constexpr T* operator->() { return checked_value(); }
  constexpr const T* operator->() const { return checked_value(); }
  constexpr T& operator*() & { return value(); }
  constexpr const T& operator*() const& { return value(); }
  constexpr T&& operator*() && { return std::move(*this).value(); }

 private:
  constexpr T* checked_value() { return const_cast<T*>(std::as_const(*this).checked_value()); }
  constexpr const T* checked_value() const {
    if (!ok()) detail::result_misused("value() of a Result that holds an error");
    return std::get_if<0>(&state_);
  }
  constexpr E* checked_error() { return const_cast<E*>(std::as_const(*this).checked_error()); }
  constexpr const E* checked_error() const {
    if (ok()) detail::result_misused("error() of a Result that holds a value");
    return std::get_if<1>(&state_);
  }

  std::variant<T, E> state_;
};

template <typename E>
class [[nodiscard]] Result<void, E> {
 public:
  using value_type = void;
  using error_type = E;

  constexpr Result() = default;
  template <typename... Args, typename = std::enable_if_t<std::is_constructible_v<E, Args&&...>>>
  constexpr Result(Failure<Args...> failure)  // NOLINT(google-explicit-constructor)
      : error_(detail::make_error<E>(std::move(failure))) {}

  [[nodiscard]] constexpr bool ok() const { return !error_.has_value(); }
  [[nodiscard]] constexpr bool has_value() const { return ok(); }
  constexpr explicit operator bool() const { return ok(); }

  /// Precondition: !ok().
  constexpr const E& error() const& { return *checked_error(); }
  constexpr E& error() & { return *checked_error(); }
  constexpr E error() && { return std::move(*checked_error()); }

 private:
  constexpr E* checked_error() { return const_cast<E*>(std::as_const(*this).checked_error()); }
  constexpr const E* checked_error() const {
    if (ok()) detail::result_misused("error() of a Result that holds no error");
    return &*error_;
  }

  std::optional<E> error_;
};

}  // namespace dh3
