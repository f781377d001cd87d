#pragma once
/// Contract checks: a failed check is a bug in the caller or in priormap, never bad user input
/// (that is reported through Diagnostic). A failed check throws ContractError with file and line.

#include <stdexcept>
#include <string>

namespace priormap {

/// Thrown by PRIORMAP_CHECK when a precondition or invariant does not hold.
class ContractError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

namespace detail {
[[noreturn]] void FailCheck(const char* file, int line, const char* condition,
                            const std::string& message);
}  // namespace detail

}  // namespace priormap

/// Checks `condition` in every build; `message` is any expression convertible to std::string.
#define PRIORMAP_CHECK(condition, message)                                      \
  do {                                                                          \
    if (!(condition)) {                                                         \
      ::priormap::detail::FailCheck(__FILE__, __LINE__, #condition, (message)); \
    }                                                                           \
  } while (false)

/// As PRIORMAP_CHECK, but compiled out of release builds; for hot loops.
#ifdef NDEBUG
#define PRIORMAP_DCHECK(condition, message) \
  do {                                      \
  } while (false)
#else
#define PRIORMAP_DCHECK(condition, message) PRIORMAP_CHECK(condition, message)
#endif
