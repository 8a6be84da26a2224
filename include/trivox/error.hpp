/// @file trivox/error.hpp
/// @brief The one exception type of trivox, with the context a user needs to fix the input.
#pragma once
#include <stdexcept>
#include <string>

namespace trivox {

/// Why an operation stopped. The command line maps `bad_input` to exit code 2 and `failed` to 1.
enum class ErrorKind {
  bad_input,  ///< malformed file, option or geometry: the user must change the input
  failed,     ///< valid input on which the operation could not succeed (invalid Jacobian, ...)
};

/// An error with context. Messages read "<where>: <what was found>; expected <what>", and each
/// layer that knows more (the file name, a JSON pointer) prepends it with `within`.
class Error : public std::runtime_error {
public:
  explicit Error(std::string message, ErrorKind kind = ErrorKind::bad_input)
      : std::runtime_error(std::move(message)), kind_(kind) {}

  ErrorKind kind() const noexcept { return kind_; }

  /// The same error, its message prefixed by `context + ": "`.
  Error within(const std::string& context) const {
    return Error(context + ": " + what(), kind_);
  }

private:
  ErrorKind kind_;
};

}  // namespace trivox
