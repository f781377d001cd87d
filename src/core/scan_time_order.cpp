#include "scan_time_order.hpp"

#include <fmt/format.h>

namespace priormap::detail {

std::optional<ScanTimeOrder::Previous> ScanTimeOrder::Note(std::string_view channel,
                                                           std::size_t scan, double timestamp,
                                                           int line) {
  for (auto& [name, last] : last_) {
    if (name != channel) continue;
    const Previous previous = last;
    last = {scan, timestamp, line};
    if (timestamp < previous.timestamp) return previous;
    return std::nullopt;
  }
  last_.emplace_back(std::string(channel), Previous{scan, timestamp, line});
  return std::nullopt;
}

void ScanTimeOrder::Warn(Diagnostic where, std::string_view channel, std::size_t scan,
                         double timestamp, const Previous& previous) {
  ++count_;
  if (count_ > kListed + 1) return;
  if (count_ == kListed + 1) {
    first_unlisted_ = std::move(where);
    first_unlisted_scan_ = scan;
    return;
  }
  const std::string of_channel = channel.empty() ? "" : fmt::format(" {}", channel);
  const std::string at_line =
      previous.line > 0 ? fmt::format(" at line {}", previous.line) : std::string();
  where.message = fmt::format(
                      "scan {} is stamped {} s, {:.3g} s before the previous{} scan (scan {}{}, "
                      "stamped {} s); the scans are kept in the file's order",
                      scan, timestamp, previous.timestamp - timestamp, of_channel, previous.scan,
                      at_line, previous.timestamp) +
                  where.message;
  warnings_.push_back(std::move(where));
}

std::vector<Diagnostic> ScanTimeOrder::Warnings() && {
  if (count_ > kListed) {
    Diagnostic summary = std::move(first_unlisted_);
    const std::size_t more = count_ - kListed;
    summary.message =
        (more == 1 ? fmt::format("1 more scan is stamped before the previous scan of its "
                                 "channel, scan {} here",
                                 first_unlisted_scan_)
                   : fmt::format("{} more scans are stamped before the previous scan of their "
                                 "channel, the first of them scan {} here",
                                 more, first_unlisted_scan_)) +
        "; the scans are kept in the file's order" + summary.message;
    warnings_.push_back(std::move(summary));
  }
  return std::move(warnings_);
}

}  // namespace priormap::detail
