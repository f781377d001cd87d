#include <fmt/format.h>

#include <priormap/core/check.hpp>

namespace priormap::detail {

void FailCheck(const char* file, int line, const char* condition, const std::string& message) {
  throw ContractError(fmt::format("{}:{}: check failed: {}: {}", file, line, condition, message));
}

}  // namespace priormap::detail
