// End-to-end tests of `priormap prf`: the prior statistics as JSON, reproducible by seed, and
// bad options reported without output.
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"

namespace priormap {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

class PrfCli : public priormap::testing::CliFixture {};

TEST_F(PrfCli, PriorStatsPrintsEstimatesWithTheirClosedForms) {
  const auto r =
      Run({"prf", "prior-stats", "--p", "2", "--window", "0.5", "--samples", "400", "--thin", "50",
           "--burn-in", "20000", "--seed", "4", "--distances", "0.05,0.2"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json out = json::parse(r.out);
  // In a 0.5 × 0.5 window with p = 2: p·perimeter + 4πp²·area = 4 + 4π.
  EXPECT_NEAR(out["expected_edges"].get<double>(), 4.0 + 4.0 * 3.14159265358979, 1e-9);
  EXPECT_GT(out["mean_edges"].get<double>(), 0.0);
  EXPECT_GT(out["mean_edges_se"].get<double>(), 0.0);
  EXPECT_EQ(out["black_fraction"]["closed_form"].get<double>(), 0.5);
  ASSERT_EQ(out["same_colour"].size(), 2u);
  EXPECT_DOUBLE_EQ(out["same_colour"][0]["distance"].get<double>(), 0.05);
  EXPECT_NEAR(out["same_colour"][1]["closed_form"].get<double>(),
              0.5 * (1.0 + std::exp(-4.0 * 2.0 * 0.2)), 1e-12);
  EXPECT_NEAR(out["crossings"][1]["mean"]["closed_form"].get<double>(), 0.8, 1e-12);
  EXPECT_EQ(out["steps"].get<int>(), 20000 + 400 * 50);
  for (const char* move : {"triangle_birth", "vertex_death", "local_recolor", "slide"})
    EXPECT_GT(out["acceptance"][move]["proposed"].get<int>(), 0) << move;
  // The same seed gives the same chain.
  const auto again =
      Run({"prf", "prior-stats", "--p", "2", "--window", "0.5", "--samples", "400", "--thin", "50",
           "--burn-in", "20000", "--seed", "4", "--distances", "0.05,0.2"});
  ASSERT_EQ(again.status, 0);
  EXPECT_EQ(json::parse(again.out)["mean_edges"], out["mean_edges"]);
}

TEST_F(PrfCli, PriorStatsWithSomeMoveKindsOnly) {
  const auto r = Run(
      {"prf", "prior-stats", "--samples", "100", "--burn-in", "0", "--moves", "triangle,vertex"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json out = json::parse(r.out);
  EXPECT_GT(out["acceptance"]["triangle_birth"]["proposed"].get<int>(), 0);
  EXPECT_EQ(out["acceptance"]["slide"]["proposed"].get<int>(), 0);
  EXPECT_EQ(out["acceptance"]["corner_birth"]["proposed"].get<int>(), 0);
}

TEST_F(PrfCli, PriorStatsRejectsBadOptions) {
  EXPECT_THAT(RunFailing({"prf", "prior-stats", "--p", "0"}).err,
              HasSubstr("--p: 0 is not positive"));
  EXPECT_THAT(RunFailing({"prf", "prior-stats", "--moves", "teleport"}).err,
              HasSubstr("unknown move kind 'teleport'"));
  EXPECT_THAT(RunFailing({"prf", "prior-stats", "--window", "2", "--distances", "3"}).err,
              HasSubstr("--distances: 3 is not inside (0, window = 2)"));
  EXPECT_THAT(RunFailing({"prf", "prior-stats", "--samples", "10"}).err,
              HasSubstr("--samples must be at least 80"));
  EXPECT_NE(RunFailing({"prf"}).status, 0);
}

}  // namespace
}  // namespace priormap
