// SPDX-License-Identifier: MIT
// Errors as values: every fallible vkcloth call returns Result<T> (a value or an Error).
// The library never calls exit() and never throws across its API.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <variant>

namespace vkcloth {

/// What went wrong, coarse enough for a caller to branch on (the CLI maps these to exit codes).
enum class ErrorCode : std::uint32_t {
  invalid_argument, ///< a parameter, scene key or size is out of its domain (CLI exit 2)
  io,               ///< a file could not be read or written (CLI exit 2)
  parse,            ///< a scene file is not valid JSON or has the wrong shape (CLI exit 2)
  diverged,         ///< the simulation produced NaN/inf or a runaway position (CLI exit 3)
  no_device,        ///< no usable Vulkan device (CLI exit 4)
  vulkan,           ///< a Vulkan call failed; see Error::vk_result
  out_of_memory,    ///< host or device memory exhausted
  unsupported,      ///< the device lacks a feature or limit the request needs
};

/// An error a person can act on: `message` names the problem and the offending value.
struct Error {
  ErrorCode code = ErrorCode::invalid_argument;
  std::string message;
  std::int32_t vk_result = 0; ///< the VkResult when code == vulkan, else 0
};

inline const char* to_string(ErrorCode c) {
  switch (c) {
  case ErrorCode::invalid_argument:
    return "invalid argument";
  case ErrorCode::io:
    return "i/o error";
  case ErrorCode::parse:
    return "parse error";
  case ErrorCode::diverged:
    return "simulation diverged";
  case ErrorCode::no_device:
    return "no Vulkan device";
  case ErrorCode::vulkan:
    return "Vulkan error";
  case ErrorCode::out_of_memory:
    return "out of memory";
  case ErrorCode::unsupported:
    return "unsupported";
  }
  return "error";
}

inline Error make_error(ErrorCode code, std::string message) {
  return Error{code, std::move(message), 0};
}

/// Either a T or an Error. Small stand-in for std::expected (not in the C++20 library we target).
template <typename T> class [[nodiscard]] Result {
public:
  Result(T value) : v_(std::move(value)) {}
  Result(Error error) : v_(std::move(error)) {}

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  const Error& error() const { return std::get<1>(v_); }

private:
  std::variant<T, Error> v_;
};

template <> class [[nodiscard]] Result<void> {
public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}
  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const { return error_; }

private:
  Error error_;
  bool ok_ = true;
};

} // namespace vkcloth

/// Propagates an error from an expression returning Result<...>.
#define VKCLOTH_TRY(expr)                                                                                    \
  do {                                                                                                       \
    if (auto vkcloth_try_r_ = (expr); !vkcloth_try_r_.ok())                                                  \
      return vkcloth_try_r_.error();                                                                         \
  } while (0)
