// Status and StatusOr<T>: how the library reports failures that depend on the
// data or on user input (bad files, bad options, unidentifiable problems).
// The library never throws, exits or prints; CHECK is for programmer errors.

#ifndef IMUSYSID_STATUS_H_
#define IMUSYSID_STATUS_H_

#include <optional>
#include <string>
#include <utility>

namespace imusysid {

enum class StatusCode {
  kOk = 0,
  // The input (a file, a flag, an option value) is wrong. CLI exit code 2.
  kInvalidArgument,
  // A named thing (file, estimator, model, topic) does not exist. Exit code 2.
  kNotFound,
  // The input is well formed but cannot support the request (for example too
  // few samples, or a model an estimator cannot fit). Exit code 2.
  kFailedPrecondition,
  // Writing or reading the file system failed. Exit code 1.
  kIoError,
  // A bug or an unexpected numerical failure. Exit code 1.
  kInternal,
};

const char* StatusCodeToString(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message)
      : code_(code), message_(std::move(message)) {}

  static Status Ok() { return Status(); }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // "INVALID_ARGUMENT: message", or "OK".
  std::string ToString() const;

  // Returns a copy whose message is "prefix: message" (used to add context such
  // as a file name while an error travels up).
  Status WithPrefix(const std::string& prefix) const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

Status InvalidArgumentError(std::string message);
Status NotFoundError(std::string message);
Status FailedPreconditionError(std::string message);
Status IoError(std::string message);
Status InternalError(std::string message);

namespace internal {
// Aborts with the status message: accessing a missing value is a bug.
[[noreturn]] void DieOnBadStatusAccess(const Status& status);
}  // namespace internal

// Either a value or a non-OK Status. Accessing the value of a non-OK StatusOr
// is a programmer error (CHECK).
template <typename T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(const Status& status) : status_(status) {  // NOLINT: implicit
    if (status_.ok()) {
      internal::DieOnBadStatusAccess(
          InternalError("StatusOr built from an OK Status without a value"));
    }
  }
  StatusOr(T value) : value_(std::move(value)) {}  // NOLINT: implicit

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }

  const T& value() const& {
    if (!ok()) internal::DieOnBadStatusAccess(status_);
    return *value_;
  }
  T& value() & {
    if (!ok()) internal::DieOnBadStatusAccess(status_);
    return *value_;
  }
  T&& value() && {
    if (!ok()) internal::DieOnBadStatusAccess(status_);
    return std::move(*value_);
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

 private:
  Status status_;
  std::optional<T> value_;
};

}  // namespace imusysid

// Returns early with the status of `expr` if it is not OK.
#define IMUSYSID_RETURN_IF_ERROR(expr)                   \
  do {                                                   \
    ::imusysid::Status imusysid_status_ = (expr);        \
    if (!imusysid_status_.ok()) return imusysid_status_; \
  } while (false)

#endif  // IMUSYSID_STATUS_H_
