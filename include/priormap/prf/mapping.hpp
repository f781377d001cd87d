#pragma once
/// PRF mapping from localized laser or sonar data (Paskin & Thrun, Sec. 2–3; sonar's data in
/// sonar_mapping.hpp): several Metropolis–Hastings chains of the posterior in parallel (oneTBB),
/// each recording the running estimates after its burn-in and traces for convergence (the
/// log-posterior and the colours of fixed points, whose split-R̂ across chains is reported), and
/// optionally simulated annealing from the best chain's final state to a MAP polygonal map.

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <priormap/prf/coloring.hpp>
#include <priormap/prf/data_term.hpp>
#include <priormap/prf/laser_data.hpp>
#include <priormap/prf/laser_model.hpp>
#include <priormap/prf/moves.hpp>
#include <priormap/prf/replica_exchange.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {

/// A stage of the burn-in on 1/stride of the readings only (all sensor positions kept): steps
/// that cost a fraction of full ones and bring the chain near the posterior before the full data
/// refine it. The samples are taken on all readings, so the posterior sampled is unchanged.
struct ThinnedBurnIn {
  int stride = 1;
  std::uint64_t steps = 0;
};

/// A stage of the burn-in right after the thinned ones, on every reading, at a temperature
/// above 1. It is meant for a chain that the thinned stages left with a wrong structure (a wedge
/// across a room, a wall a door's width off), which at temperature 1 would keep it. Measured on
/// the sonar log of docs/benchmarks.md ("2026-11-27 (late)"): it lifts chains close to the right
/// structure and can push one into a wrong one. The rest of the burn-in is at temperature 1, so
/// the chain settles before the samples.
struct WarmBurnIn {
  double temperature = 1.0;
  std::uint64_t steps = 0;
};

struct MappingOptions {
  SamplerOptions sampler;  ///< p, move weights, scales (temperature is set by the run)
  LaserModel model;
  double cell_size = 0.5;          ///< of the edge and beam indices, m
  double margin = 1.0;             ///< window around the data, m
  double raster_resolution = 0.1;  ///< of the P(black) and white-fraction rasters, m
  /// δ of the guided triangle births, whose guide points are the readings' end points (not
  /// max readings); their pair radius is the sampler's birth_scale. m.
  double guide_jitter = 0.05;
  std::uint64_t samples = 1000000;  ///< steps recorded per chain, after the burn-in
  std::uint64_t burn_in = 200000;   ///< steps per chain
  /// The chains start the burn-in at this temperature and cool geometrically to 1 over its
  /// first half (in blocks of kTemperatureBlock steps), so that they cross barriers between
  /// modes early; samples are taken at temperature 1 only. 1: no tempering.
  double burn_in_temperature = 1.0;
  /// The first steps of the burn-in, stage after stage, on thinned data; their steps count
  /// towards burn_in, whose remaining steps use every reading.
  std::vector<ThinnedBurnIn> thinned_burn_in;
  /// Every this many steps of a thinned stage, the stage goes on with the next of its stride's
  /// disjoint shares of the readings (KeptByThinning's phases), so that over stride × rotation
  /// steps every reading has counted once. 0: one share for the whole stage. A fixed share
  /// draws the chain to its own posterior, whose faces the rest of the data do not all hold
  /// (docs/benchmarks.md, "2026-12-03 (evening)").
  std::uint64_t thinned_rotation = 0;
  /// Whether a thinned stage counts each kept reading's log-likelihood stride times, which makes
  /// it an unbiased estimate of all the readings' (false: once, which tempers the stage as
  /// T = stride would).
  bool thinned_weighed = false;
  /// After the thinned stages; its steps too count towards burn_in. Within it the temperature is
  /// the larger of its own and the tempered burn-in's.
  WarmBurnIn warm_burn_in;
  /// Replica exchange through the burn-in (replica_exchange.hpp): each chain runs this many
  /// replicas (1: none) at temperatures rising geometrically from 1 to replica_temperature
  /// (times the tempered burn-in's), which offer swaps every kExchangeEvery steps, for the
  /// first replica_steps of the burn-in (0: all of it); then the chain goes on from the cold
  /// replica. Those steps cost `burn_in_replicas` times as much.
  int burn_in_replicas = 1;
  double replica_temperature = 4.0;
  std::uint64_t replica_steps = 0;
  /// At the ladder's end the chain goes on from the replica of highest log-posterior instead of
  /// the cold one (ReplicaLadder::TakeBest): a best-of-K start.
  bool replica_pick_best = false;
  int chains = 2;
  std::uint64_t seed = 1;
  std::uint64_t trace_every = 1000;  ///< steps between trace records (R̂)
  int trace_points = 32;             ///< fixed points whose colours enter R̂
  std::uint64_t anneal_steps = 0;    ///< 0: no annealing
  double anneal_final_temperature = 0.01;
  /// Steps per chain between progress calls (and between chunks of work).
  std::uint64_t chunk = 20000;
};

/// Steps run at one temperature of the tempered burn-in.
inline constexpr std::uint64_t kTemperatureBlock = 10000;
/// Steps of every replica between exchange rounds (a divisor of kTemperatureBlock).
inline constexpr std::uint64_t kExchangeEvery = 1000;
/// The burn-in's temperature at step s: that of the tempered burn-in (by its block; 1 from the
/// middle of the burn-in on), raised to the warm stage's within it.
[[nodiscard]] double BurnInTemperature(const MappingOptions& options, std::uint64_t step);
/// Where the temperature of step s ends: at the next block, the middle of the burn-in, or the
/// warm stage's start or end, whichever comes first (the largest step count when the
/// temperature does not change from s on).
[[nodiscard]] std::uint64_t BurnInTemperatureEnd(const MappingOptions& options, std::uint64_t step);
/// The steps [begin, end) of the warm stage (empty without one).
struct WarmStage {
  std::uint64_t begin = 0;
  std::uint64_t end = 0;
};
[[nodiscard]] WarmStage WarmStageOf(const MappingOptions& options);

/// Whether reading i is in share `phase` (0 ≤ phase < stride) of the `stride` disjoint shares of
/// about 1/stride of the readings each that a thinned stage keeps: a fixed pseudo-random choice
/// (every stride-th reading would pick the same transducer of every ring, or the same beam of
/// every scan, when the stride divides their count).
[[nodiscard]] bool KeptByThinning(std::size_t i, int stride, int phase = 0);

/// The share of the readings used at step s (stride 1 past the thinned stages), and the step
/// where it ends: at its stage's end or, with thinned_rotation, at the next rotation.
struct BurnInStage {
  int stride = 1;
  int phase = 0;  ///< KeptByThinning's
  std::uint64_t end = 0;
};
[[nodiscard]] BurnInStage BurnInStageAt(const MappingOptions& options, std::uint64_t step);

/// How one session of a run is carried out; none of it changes the result. A run stopped
/// (by `stop`, `stop_after_steps` or a crash) and resumed from its checkpoints ends exactly
/// as the uninterrupted run of the same options and seed.
struct MappingSession {
  /// Where the chains write their checkpoints (empty: none).
  std::filesystem::path checkpoint_directory;
  double checkpoint_every_s = 5.0;
  /// Continue from the checkpoints in checkpoint_directory (chains without one start afresh).
  bool resume = false;
  /// Each chain (and the annealing) stops, checkpointed, after this many steps in this
  /// session; 0: no limit.
  std::uint64_t stop_after_steps = 0;
  /// Set from elsewhere (a signal handler) to stop every chain, checkpointed, at its next
  /// chunk boundary.
  const std::atomic<bool>* stop = nullptr;
  /// A second flag with the same effect: a study sets it when one of its cases fails, so that
  /// the other cases stop too rather than run to their end before the failure is reported.
  const std::atomic<bool>* also_stop = nullptr;
};

struct ChainSummary {
  MoveCounters counters{};
  /// At the chain's last step (log_prior + log_likelihood): chains apart in the likelihood
  /// explain the readings differently.
  double log_posterior = 0.0;
  double log_prior = 0.0;
  double log_likelihood = 0.0;
  /// The chain's state at the session's end, to compare chains that end in different modes
  /// structure by structure.
  std::optional<Coloring> last;
  int edges = 0;
  std::vector<double> log_posterior_trace;
  std::vector<std::vector<double>> point_traces;  ///< per trace point: 1 black, 0 white
  std::vector<SwapCounter> swaps;                 ///< of the burn-in's replicas, per adjacent pair
  /// This chain's P(black) per cell on MappingResult::raster: which chain holds what where the
  /// chains disagree (MappingResult::chain_spread shows only where).
  Eigen::MatrixXd black_fraction;
};

/// A chain as it stood at its latest progress report.
struct ChainProgress {
  bool reported = false;  ///< false until the chain reports this session (or is restored finished)
  double log_posterior = 0.0;  ///< under its stage's data:
  int data_stride = 1;         ///< 1/data_stride of the readings (KeptByThinning); 1: all of them
};

/// The annealing (MappingOptions::anneal_steps) as it stood at its latest progress report.
struct AnnealingProgress {
  std::size_t chain = 0;       ///< the chain it continues, the one that ended highest
  double temperature = 1.0;    ///< of its latest chunk
  double log_posterior = 0.0;  ///< on all the readings, untempered
};

/// Every report shows all the chains, each at its own latest report: a line built from the
/// reporting chain alone would jump between chains whose log-posteriors differ by their modes.
/// The steps are those of the chains and of the annealing, so that a run's progress reaches
/// steps_total when its last step, not its chains' last, is done.
struct MappingProgress {
  std::uint64_t steps_done = 0;  ///< over all chains and the annealing, restored ones included
  /// chains × (burn_in + samples), plus the annealing's steps (see AnnealingSteps).
  std::uint64_t steps_total = 0;
  std::uint64_t steps_resumed = 0;  ///< of steps_done, restored from checkpoints
  double seconds = 0.0;
  std::vector<ChainProgress> chains;  ///< one per chain, in chain order
  /// Summed over the chains' latest reports; once the annealing reports, its counters stand for
  /// its chain's (they go on from them).
  MoveCounters counters{};
  /// Set from the annealing's first report this session on (the chains have all ended then).
  std::optional<AnnealingProgress> annealing;
};

struct MappingResult {
  Window window;
  CellGrid raster;
  Eigen::MatrixXd black_fraction;  ///< pooled over chains, row 0 at the bottom
  Eigen::MatrixXd white_fraction;
  /// The largest minus the smallest chain's P(black), per cell: where the chains disagree
  /// (what R̂ only summarizes); zero with one chain.
  Eigen::MatrixXd chain_spread;
  std::vector<ChainSummary> chains;
  std::vector<Vec2> trace_points;
  double rhat_log_posterior = 0.0;
  double rhat_point_colours = 0.0;  ///< the largest over the trace points
  double wall_time_s = 0.0;
  double sampling_time_s = 0.0;   ///< the chains' (restoring their checkpoints included)
  double annealing_time_s = 0.0;  ///< the annealing's (0 without one)
  /// The steps taken in this session (not those restored from checkpoints): all chains and
  /// their replicas, burn-in included, and the annealing.
  std::uint64_t proposals = 0;
  std::optional<Coloring> map;  ///< the annealed MAP coloring
  double map_log_posterior = 0.0;
  /// False when the session stopped before the end (the estimates and R̂ are then unset).
  bool complete = true;
  /// Steps restored from checkpoints: all chains' and the annealing's.
  std::uint64_t resumed_steps = 0;

  /// `proposals` over the seconds they took (the chains' and the annealing's); 0 before any.
  [[nodiscard]] double ProposalsPerSecond() const;
};

/// What a run needs of its data, whatever the sensor (laser beams, sonar cones).
struct MappingData {
  Window window;
  std::vector<Vec2> trace_points;  ///< whose colours enter R̂
  std::vector<Vec2> guide_points;  ///< of the guided triangle births: where readings ended
  /// Identifies the run (data, data model and options): checkpoints of another are refused.
  std::uint64_t fingerprint = 0;
  /// Identifies the likelihood alone (the readings, the sensors and the data model), not the
  /// prior nor the sampler: runs of other seeds or sampler settings share it, runs of another
  /// log or data model do not (`priormap prf rhat` pools runs by it).
  std::uint64_t data_fingerprint = 0;
  /// A fresh data term, one per chain.
  std::function<std::unique_ptr<DataTerm>()> make_data_term;
  /// A fresh data term of the readings KeptByThinning(i, stride, phase), with every sensor
  /// position (for the thinned burn-in and the screen; may be empty when the data offer none).
  std::function<std::unique_ptr<DataTerm>(int stride, int phase)> make_thinned_data_term;
  /// Where every chain starts (a coloring of `window` with the run's cell size, of nonzero
  /// likelihood); the empty all-white coloring when unset.
  std::optional<Coloring> start;
};

/// The steps the annealing takes: options.anneal_steps rounded down to a whole number of its
/// temperature stages, at least one step per stage (0 without annealing).
[[nodiscard]] std::uint64_t AnnealingSteps(const MappingOptions& options);

/// The most cells the rasters of a run's window may have at its raster resolution (each chain
/// keeps several, some 40 bytes a cell in all); the CLI and the Python module refuse finer ones.
inline constexpr double kMaxRasterCells = 1e8;

/// Empty when the rasters of `window` at `resolution` m have at most kMaxRasterCells cells, else
/// what is wrong ("the 4.0 m x 6.0 m window would make rasters of 2.4e+09 cells, more than
/// 1e+08"): a resolution too fine would end in a bare bad_alloc once the chains had started.
[[nodiscard]] std::string RasterSizeProblem(const Window& window, double resolution);

/// The laser run's data: the window around the beams (options.margin), the trace and guide
/// points from the beams that hit, the LaserLikelihood of options.model.
[[nodiscard]] MappingData LaserMappingData(std::shared_ptr<const LaserData> data,
                                           const MappingOptions& options);

/// Runs the chains; `progress` (may be empty) is called from the chains' threads, serialized.
/// Throws BinaryFormatError when resuming from a damaged checkpoint or one of another run, and
/// IoError when a checkpoint cannot be written.
[[nodiscard]] MappingResult RunMapping(const MappingData& data, const MappingOptions& options,
                                       const std::function<void(const MappingProgress&)>& progress,
                                       const MappingSession& session = {});
/// RunMapping of LaserMappingData(data, options).
[[nodiscard]] MappingResult RunMapping(std::shared_ptr<const LaserData> data,
                                       const MappingOptions& options,
                                       const std::function<void(const MappingProgress&)>& progress,
                                       const MappingSession& session = {});

}  // namespace priormap::prf
