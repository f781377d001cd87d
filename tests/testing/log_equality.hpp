#pragma once
// Exact comparison of scans, logs and scenes, as the round-trip tests (write, read back) need it:
// NaN equals NaN; every other number must have the same bits (so 0.0 differs from -0.0). A
// failure names the first differences (at most ten), e.g. "scan 3: ranges[7]: 1.5 vs 1.25".
// Every field is compared, but for Log::order, compared as the order it gives (RecordOrder).

#include <gtest/gtest.h>

#include <priormap/core/log.hpp>
#include <priormap/core/scan.hpp>
#include <priormap/core/scene.hpp>

namespace priormap::testing {

::testing::AssertionResult SameScan(const Scan& a, const Scan& b);
::testing::AssertionResult SameLog(const Log& a, const Log& b);
::testing::AssertionResult SameScene(const Scene& a, const Scene& b);

}  // namespace priormap::testing
