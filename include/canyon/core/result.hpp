#pragma once
// Result<T>: the value or an Error that says what was wrong and where (C++20 has no std::expected).
// Bad data returns a Result; programmer mistakes are assertions; nothing in the core exits or aborts.

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace canyon {

/// What went wrong and where: a file and line for input data, empty when not about a file.
struct Error {
  Error() = default;
  Error(std::string message_, std::string file_ = {}, int line_ = 0)  // NOLINT(google-explicit-constructor)
      : message(std::move(message_)), file(std::move(file_)), line(line_) {}

  std::string message;  ///< human-readable cause, e.g. "bad satellite number 'G9x'"
  std::string file;     ///< input file path, or empty
  int line = 0;         ///< 1-based line number in `file`, 0 when not applicable

  /// "file:line: message", or just the message when no file is known.
  [[nodiscard]] std::string to_string() const {
    if (file.empty()) {
      return message;
    }
    return line > 0 ? file + ":" + std::to_string(line) + ": " + message : file + ": " + message;
  }
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : storage_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : storage_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  [[nodiscard]] bool ok() const { return std::holds_alternative<T>(storage_); }
  explicit operator bool() const { return ok(); }

  [[nodiscard]] T& value() & {
    assert(ok());
    return std::get<T>(storage_);
  }
  [[nodiscard]] const T& value() const& {
    assert(ok());
    return std::get<T>(storage_);
  }
  [[nodiscard]] T&& value() && {
    assert(ok());
    return std::get<T>(std::move(storage_));
  }
  [[nodiscard]] const Error& error() const {
    assert(!ok());
    return std::get<Error>(storage_);
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::variant<T, Error> storage_;
};

/// Result of an operation with no value.
struct Ok {};
using Status = Result<Ok>;

}  // namespace canyon
