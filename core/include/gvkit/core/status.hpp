#pragma once
// Status and Result<T>: the one way gvkit reports bad data from the world (files, bitstreams,
// devices, user options). The message names the input and what is wrong, e.g.
// "take3.gvid: frame 41: CRC mismatch". Broken contracts inside the program are not Status:
// they are GVKIT_CHECK failures, which throw ContractError.

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace gvkit {

enum class StatusCode {
  kOk = 0,
  kInvalidArgument,  // a user option or parameter out of range
  kNotFound,         // a file or device that does not exist
  kIoError,          // read/write failed (permissions, disk full, device gone)
  kCorruptData,      // bytes that do not parse: truncated file, bad CRC, NaN where numbers belong
  kUnsupported,      // a valid input this build cannot handle (format, pixel type, version)
  kFailedPrecondition,  // input is well formed but unusable (parallel rays, no face found)
  kInternal,
};

// Human-readable name of a code ("corrupt data", ...).
const char* status_code_name(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;  // ok
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status ok() { return {}; }
  bool is_ok() const { return code_ == StatusCode::kOk; }
  explicit operator bool() const { return is_ok(); }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }

  // Returns a copy whose message is "<context>: <message>", for adding the file or frame name
  // as an error travels outwards.
  Status with_context(const std::string& context) const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

Status invalid_argument(std::string message);
Status not_found(std::string message);
Status io_error(std::string message);
Status corrupt_data(std::string message);
Status unsupported(std::string message);
Status failed_precondition(std::string message);

// Thrown by GVKIT_CHECK when an internal contract is broken (a bug, never bad input).
class ContractError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

[[noreturn]] void fail_check(const char* condition, const char* file, int line,
                             const std::string& message);

// A value or the Status that explains why there is none. Accessing value() of a failed Result
// is a contract violation (throws ContractError).
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}         // NOLINT(google-explicit-constructor)
  Result(Status status) : status_(std::move(status)) {  // NOLINT(google-explicit-constructor)
    if (status_.is_ok()) fail_check("!status.is_ok()", __FILE__, __LINE__, "Result from ok Status");
  }
  // The value built in place (for types without a cheap move, e.g. OpenMesh meshes).
  template <typename... Args>
  explicit Result(std::in_place_t, Args&&... args)
      : value_(std::in_place, std::forward<Args>(args)...) {}

  bool is_ok() const { return value_.has_value(); }
  explicit operator bool() const { return is_ok(); }
  const Status& status() const { return status_; }

  T& value() & { return checked(); }
  const T& value() const& { return const_cast<Result*>(this)->checked(); }
  T&& value() && { return std::move(checked()); }
  T* operator->() { return &checked(); }
  const T* operator->() const { return &const_cast<Result*>(this)->checked(); }
  T& operator*() & { return checked(); }
  const T& operator*() const& { return const_cast<Result*>(this)->checked(); }

 private:
  T& checked() {
    if (!value_)
      fail_check("is_ok()", __FILE__, __LINE__, "value() of a failed Result: " + status_.message());
    return *value_;
  }
  std::optional<T> value_;
  Status status_;
};

}  // namespace gvkit

// Internal contract check: throws gvkit::ContractError naming the condition and location.
#define GVKIT_CHECK(cond, ...)                                                             \
  do {                                                                                     \
    if (!(cond)) ::gvkit::fail_check(#cond, __FILE__, __LINE__, std::string{__VA_ARGS__}); \
  } while (0)

// Propagate a failed Status (or a failed Result's status) to the caller.
#define GVKIT_RETURN_IF_ERROR(expr)                   \
  do {                                                \
    ::gvkit::Status gvkit_status_ = (expr);           \
    if (!gvkit_status_.is_ok()) return gvkit_status_; \
  } while (0)

#define GVKIT_CONCAT_INNER(a, b) a##b
#define GVKIT_CONCAT(a, b) GVKIT_CONCAT_INNER(a, b)
// GVKIT_ASSIGN_OR_RETURN(auto x, make_x()); declares x from a Result or returns its Status.
#define GVKIT_ASSIGN_OR_RETURN(decl, expr) \
  GVKIT_ASSIGN_OR_RETURN_IMPL(GVKIT_CONCAT(gvkit_result_, __LINE__), decl, expr)
#define GVKIT_ASSIGN_OR_RETURN_IMPL(tmp, decl, expr) \
  auto tmp = (expr);                                 \
  if (!tmp.is_ok()) return tmp.status();             \
  decl = std::move(tmp).value()
