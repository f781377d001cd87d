// R̂ pooled over runs: the traces' CSV files (and their errors, at file:line:col), the pooled
// value against SplitRhat over every chain, and what makes runs unfit to pool. Runs whose own
// chains agree but whose seeds sit apart pass their own R̂ and fail the pooled one.
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/pooled_rhat.hpp>
#include <priormap/prf/rhat.hpp>

namespace priormap::prf {
namespace {

using ::testing::HasSubstr;

TEST(LogPosteriorTrace, ParsesSamplesAndChains) {
  const auto traces =
      ParseLogPosteriorTrace("sample,chain0,chain1\n1000,1.5,2\r\n2000,-3,4e2\n\n", "t.csv");
  ASSERT_TRUE(traces.ok()) << traces.error();
  EXPECT_EQ(traces.value().samples, (std::vector<std::uint64_t>{1000, 2000}));
  EXPECT_EQ(traces.value().log_posterior,
            (std::vector<std::vector<double>>{{1.5, -3.0}, {2.0, 400.0}}));
  EXPECT_TRUE(traces.value().point_colours.empty());
}

TEST(LogPosteriorTrace, ReportsWhereAndWhatWasExpected) {
  EXPECT_THAT(ParseLogPosteriorTrace("", "t.csv").error(), HasSubstr("t.csv:1:1:"));
  EXPECT_THAT(ParseLogPosteriorTrace("sample,chain0,chainX\n", "t.csv").error(),
              HasSubstr("t.csv:1:15: error: expected the column 'chain1', found 'chainX'"));
  EXPECT_THAT(ParseLogPosteriorTrace("step,chain0\n", "t.csv").error(),
              HasSubstr("t.csv:1:1: error: expected the column 'sample'"));
  EXPECT_THAT(ParseLogPosteriorTrace("sample,chain0\n1000,1\n2000,abc\n", "t.csv").error(),
              HasSubstr("t.csv:3:6: error: expected a finite log-posterior, found 'abc'"));
  EXPECT_THAT(ParseLogPosteriorTrace("sample,chain0\n1000,nan\n", "t.csv").error(),
              HasSubstr("t.csv:2:6:"));
  EXPECT_THAT(ParseLogPosteriorTrace("sample,chain0\n1000,1,2\n", "t.csv").error(),
              HasSubstr("t.csv:2:8: error: expected 2 values (the sample, then one per chain as "
                        "in the header), found 3"));
  EXPECT_THAT(ParseLogPosteriorTrace("sample,chain0,chain1\n1000,1\n", "t.csv").error(),
              HasSubstr("t.csv:2:7: error: expected 3 values"));
  EXPECT_THAT(ParseLogPosteriorTrace("sample,chain0\n1000,1\n1000,2\n", "t.csv").error(),
              HasSubstr("t.csv:3:1: error: expected a sample count above the last one"));
  EXPECT_THAT(ParseLogPosteriorTrace("sample,chain0\n-5,1\n", "t.csv").error(),
              HasSubstr("t.csv:2:1: error: expected a sample count"));
}

RunTraces TwoChainsTwoRecords() {
  return ParseLogPosteriorTrace("sample,chain0,chain1\n10,1,2\n20,3,4\n", "t.csv").value();
}

TEST(PointTraces, ParsesEachChainsPoints) {
  const auto traces = ParsePointTraces(
      "sample,chain0_point0,chain0_point1,chain1_point0,chain1_point1\n10,1,0,0,0\n20,1,1,0,1\n",
      "p.csv", TwoChainsTwoRecords());
  ASSERT_TRUE(traces.ok()) << traces.error();
  const auto& colours = traces.value().point_colours;
  ASSERT_EQ(colours.size(), 2u);
  EXPECT_EQ(colours[0], (std::vector<std::vector<double>>{{1, 1}, {0, 1}}));
  EXPECT_EQ(colours[1], (std::vector<std::vector<double>>{{0, 0}, {0, 1}}));
}

TEST(PointTraces, MustMatchTheLogPosteriorTrace) {
  const std::string header = "sample,chain0_point0,chain1_point0\n";
  EXPECT_THAT(ParsePointTraces(header + "10,1,0\n20,2,0\n", "p.csv", TwoChainsTwoRecords()).error(),
              HasSubstr("p.csv:3:4: error: expected a colour, 0 (white) or 1 (black), found '2'"));
  EXPECT_THAT(ParsePointTraces(header + "10,1,0\n30,1,0\n", "p.csv", TwoChainsTwoRecords()).error(),
              HasSubstr("p.csv:3:1: error: expected the sample 20, as in trace.csv, found '30'"));
  EXPECT_THAT(ParsePointTraces(header + "10,1,0\n", "p.csv", TwoChainsTwoRecords()).error(),
              HasSubstr("p.csv:2:7: error: expected 2 records, as in trace.csv, found 1"));
  EXPECT_THAT(
      ParsePointTraces(header + "10,1,0\n20,1,0\n30,1,0\n", "p.csv", TwoChainsTwoRecords()).error(),
      HasSubstr("p.csv:4:1: error: expected 2 records, as in trace.csv, found 3"));
  EXPECT_THAT(ParsePointTraces(header + "10,1,0\n20,1\n", "p.csv", TwoChainsTwoRecords()).error(),
              HasSubstr("p.csv:3:5: error: expected 3 values"));
  EXPECT_THAT(ParsePointTraces("sample,chain0_point0,chain0_point1,chain1_point0\n", "p.csv",
                               TwoChainsTwoRecords())
                  .error(),
              HasSubstr("p.csv:1:1: error: expected a column per chain and trace point"));
  EXPECT_THAT(
      ParsePointTraces("sample,chain0_point0,chain0_point0\n", "p.csv", TwoChainsTwoRecords())
          .error(),
      HasSubstr("p.csv:1:22: error: expected the column 'chain1_point0'"));
}

// A run of `chains` chains, each N(mean, 1) per record, records every 100 samples, and (when
// `points`) one point per chain that is black with probability `black`.
PooledRun NormalRun(const std::string& name, std::uint64_t seed, std::size_t chains, double mean,
                    std::size_t records, double black = -1.0) {
  Rng rng(seed * 7919 + 1);
  PooledRun run{.name = name, .chain_seeds = {}, .traces = {}};
  for (std::size_t i = 0; i < records; ++i) run.traces.samples.push_back(100 * (i + 1));
  for (std::size_t c = 0; c < chains; ++c) {
    run.chain_seeds.push_back(seed + c);
    std::vector<double> trace, colours;
    for (std::size_t i = 0; i < records; ++i) {
      trace.push_back(rng.Normal(mean, 1.0));
      colours.push_back(rng.Uniform() < black ? 1.0 : 0.0);
    }
    run.traces.log_posterior.push_back(trace);
    if (black >= 0.0) run.traces.point_colours.push_back({colours});
  }
  return run;
}

TEST(PoolRhat, IsSplitRhatOverEveryChainOfEveryRun) {
  const std::vector<PooledRun> runs = {NormalRun("a", 1, 2, 0.0, 400, 0.3),
                                       NormalRun("b", 3, 3, 0.4, 300, 0.6)};
  const auto pooled = PoolRhat(runs);
  ASSERT_TRUE(std::holds_alternative<PooledRhat>(pooled)) << std::get<std::string>(pooled);
  const PooledRhat& r = std::get<PooledRhat>(pooled);
  EXPECT_EQ(r.chains, 5u);
  EXPECT_EQ(r.records, 300u);  // the shorter run's
  std::vector<std::vector<double>> traces, colours;
  for (const PooledRun& run : runs)
    for (std::size_t c = 0; c < run.traces.log_posterior.size(); ++c) {
      traces.emplace_back(run.traces.log_posterior[c].begin(),
                          run.traces.log_posterior[c].begin() + 300);
      colours.emplace_back(run.traces.point_colours[c][0].begin(),
                           run.traces.point_colours[c][0].begin() + 300);
    }
  EXPECT_DOUBLE_EQ(r.log_posterior, SplitRhat(traces));
  ASSERT_TRUE(r.point_colours.has_value());
  EXPECT_EQ(r.points, 1u);
  EXPECT_DOUBLE_EQ(*r.point_colours, std::max(1.0, SplitRhat(colours)));
  ASSERT_EQ(r.second_half_means.size(), 5u);
  double mean = 0.0;
  for (std::size_t i = 150; i < 300; ++i) mean += runs[1].traces.log_posterior[2][i] / 150.0;
  EXPECT_NEAR(r.second_half_means[4], mean, 1e-12);
}

TEST(PoolRhat, GivesEachPointsRhatAndEachChainsShareOfBlack) {
  // Two runs of two chains that agree on point 0 (black half the time) and not on point 1
  // (black in 20 % of one run's records, 90 % of the other's).
  std::vector<PooledRun> runs = {NormalRun("a", 1, 2, 0.0, 400, 0.5),
                                 NormalRun("b", 3, 2, 0.0, 400, 0.5)};
  Rng rng(11);
  for (std::size_t r = 0; r < runs.size(); ++r)
    for (auto& chain : runs[r].traces.point_colours) {
      std::vector<double> colours;
      for (std::size_t i = 0; i < 400; ++i)
        colours.push_back(rng.Uniform() < (r == 0 ? 0.2 : 0.9) ? 1.0 : 0.0);
      chain.push_back(colours);
    }
  const auto pooled = PoolRhat(runs);
  ASSERT_TRUE(std::holds_alternative<PooledRhat>(pooled)) << std::get<std::string>(pooled);
  const PooledRhat& r = std::get<PooledRhat>(pooled);
  ASSERT_EQ(r.point_rhats.size(), 2u);
  double largest = 1.0;
  for (std::size_t k = 0; k < 2; ++k) {
    const PointRhat& point = r.point_rhats[k];
    EXPECT_EQ(point.point, k);
    std::vector<std::vector<double>> traces;
    ASSERT_EQ(point.black.size(), 4u);
    std::size_t chain = 0;
    for (const PooledRun& run : runs)
      for (const auto& colours : run.traces.point_colours) {
        traces.push_back(colours[k]);
        double black = 0.0;
        for (double c : colours[k]) black += c;
        EXPECT_DOUBLE_EQ(point.black[chain++], black / 400.0);
      }
    EXPECT_DOUBLE_EQ(point.rhat, SplitRhat(traces));
    largest = std::max(largest, point.rhat);
  }
  EXPECT_LT(r.point_rhats[0].rhat, kConvergedRhat);
  EXPECT_GT(r.point_rhats[1].rhat, kConvergedRhat);
  EXPECT_LT(r.point_rhats[1].black[1], 0.3);
  EXPECT_GT(r.point_rhats[1].black[2], 0.8);
  EXPECT_EQ(*r.point_colours, largest);
}

TEST(PoolRhat, CatchesRunsThatAgreeWithinButNotAcross) {
  // Each run's two chains sample N(0, 1) or N(3, 1): each run's own R̂ is near 1.
  const PooledRun low = NormalRun("low", 1, 2, 0.0, 1000);
  const PooledRun high = NormalRun("high", 3, 2, 3.0, 1000);
  for (const PooledRun& run : {low, high}) {
    const auto own = PoolRhat({run});
    ASSERT_TRUE(std::holds_alternative<PooledRhat>(own));
    EXPECT_LT(std::get<PooledRhat>(own).log_posterior, 1.02);
  }
  const auto pooled = PoolRhat({low, high});
  ASSERT_TRUE(std::holds_alternative<PooledRhat>(pooled));
  EXPECT_GT(std::get<PooledRhat>(pooled).log_posterior, 1.5);
  // Without point traces in every run, no colours' R̂.
  EXPECT_FALSE(std::get<PooledRhat>(pooled).point_colours.has_value());
}

TEST(PoolRhat, OneChainIsSplitInHalvesAndNoPointsGiveOne) {
  // As a run's own R̂: one chain's halves, and 1 for the colours when there are no points.
  PooledRun run = NormalRun("a", 1, 1, 0.0, 200);
  run.traces.point_colours.assign(1, {});
  const auto pooled = PoolRhat({run});
  ASSERT_TRUE(std::holds_alternative<PooledRhat>(pooled)) << std::get<std::string>(pooled);
  const PooledRhat& r = std::get<PooledRhat>(pooled);
  EXPECT_DOUBLE_EQ(r.log_posterior, SplitRhat(run.traces.log_posterior));
  ASSERT_TRUE(r.point_colours.has_value());
  EXPECT_EQ(*r.point_colours, 1.0);
  EXPECT_EQ(r.points, 0u);
}

TEST(PoolRhat, RefusesWhatCannotBePooled) {
  const auto problem = [](const std::vector<PooledRun>& runs) {
    const auto pooled = PoolRhat(runs);
    return std::holds_alternative<std::string>(pooled) ? std::get<std::string>(pooled)
                                                       : std::string("pooled");
  };
  // Seed 2 is chain 1 of the first run and chain 0 of the second.
  EXPECT_THAT(problem({NormalRun("a", 1, 2, 0.0, 10), NormalRun("b", 2, 2, 0.0, 10)}),
              HasSubstr("b: a chain draws from seed 2, as one of another run does"));
  EXPECT_THAT(problem({}), HasSubstr("at least one chain"));
  EXPECT_THAT(problem({NormalRun("a", 1, 2, 0.0, 10), NormalRun("b", 5, 2, 0.0, 3)}),
              HasSubstr("b: R-hat needs at least 4 trace records per chain; it has 3"));
  EXPECT_THAT(problem({NormalRun("a", 1, 2, 0.0, 10, 0.5), NormalRun("b", 5, 2, 0.0, 10, 0.5),
                       [] {
                         PooledRun more = NormalRun("c", 9, 2, 0.0, 10, 0.5);
                         for (auto& chain : more.traces.point_colours) chain.push_back(chain[0]);
                         return more;
                       }()}),
              HasSubstr("c traced 2 points where a traced 1"));
  PooledRun sparse = NormalRun("b", 5, 2, 0.0, 10);
  for (std::uint64_t& sample : sparse.traces.samples) sample *= 2;
  EXPECT_THAT(problem({NormalRun("a", 1, 2, 0.0, 10), sparse}),
              HasSubstr("b records sample 200 where a records sample 100"));
}

}  // namespace
}  // namespace priormap::prf
