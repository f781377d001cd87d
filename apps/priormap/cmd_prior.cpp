// priormap prior: list, check, show and evaluate priorlet files (docs/priorlet-language.md).
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <priormap/dsl/pose_independence.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

struct PriorOptions {
  std::vector<std::string> prior_path;
  std::string prior;
  bool pose_independence = false;
  bool derivatives = false;
  std::string block = "same_region";
  std::string at;
  std::uint64_t seed = 1;
};

dsl::CompiledPrior Load(const PriorOptions& o) {
  return LoadPrior(o.prior_path, o.prior);
}

void List(const PriorOptions& o) {
  const dsl::PriorLibrary library = MakePriorLibrary(o.prior_path);
  for (const dsl::PriorListing& p : library.List()) {
    fmt::print("{:<42} {}\n", p.name, p.description);
    fmt::print("{:<42} {}\n", "", p.path);
    // A file that parses can still fail to compile (an unknown name, a missing parent): naming
    // it would fail, so say so here rather than at the user's first `scan`.
    if (p.builtin) continue;
    const Result<dsl::CompiledPrior> compiled = library.Load(p.name);
    for (const Diagnostic& d : compiled.diagnostics())
      fmt::print(stderr, "priormap: warning: '{}' does not compile, {}: {}\n", p.name, d.Location(),
                 d.message);
    if (compiled) PrintPriorWarnings(compiled.value());
  }
  for (const Diagnostic& d : library.Unparsable())
    fmt::print(stderr, "priormap: warning: not listed, {}: {}\n", d.Location(), d.message);
}

// "1 equality", "2 equalities".
std::string Count(int n, const char* singular, const char* plural) {
  return fmt::format("{} {}", n, n == 1 ? singular : plural);
}

void Check(const PriorOptions& o) {
  const dsl::CompiledPrior prior = Load(o);
  fmt::print("{} ({})\n", prior.name(), prior.chain().front().path);
  for (std::size_t i = 1; i < prior.chain().size(); ++i) {
    fmt::print("  specializes: {} ({})\n", prior.chain()[i].name, prior.chain()[i].path);
  }
  fmt::print("  order: {}   max_curvature: {}\n", prior.order(),
             std::isinf(prior.max_curvature()) ? std::string("none")
                                               : fmt::format("{} 1/m", prior.max_curvature()));
  for (int b = 0; b < dsl::kNumBlockKinds; ++b) {
    const auto kind = static_cast<dsl::BlockKind>(b);
    const dsl::CompiledBlock* block = prior.block(kind);
    if (!block) {
      fmt::print("  {:<18} none (no constraint)\n", fmt::format("{}:", dsl::ToString(kind)));
      continue;
    }
    const dsl::BlockSummary& s = block->summary();
    fmt::print("  {:<18} {}, {}, {}, {} ({}); uses {}\n", fmt::format("{}:", dsl::ToString(kind)),
               Count(s.equalities, "equality", "equalities"),
               Count(s.inequalities, "inequality", "inequalities"),
               Count(s.disjunctions, "disjunction", "disjunctions"),
               Count(s.energies, "energy", "energies"),
               Count(s.scalar_terms, "scalar term", "scalar terms"),
               s.variables.empty() ? "nothing" : fmt::format("{}", fmt::join(s.variables, " ")));
  }
  if (o.pose_independence) {
    const dsl::PoseIndependenceReport report = dsl::CheckPoseIndependence(prior, 200, o.seed);
    if (report.ok()) {
      fmt::print(
          "  pose independence: ok (every term unchanged under {} random rigid motions per "
          "block)\n",
          report.configurations);
    } else {
      for (const dsl::PoseIndependenceViolation& v : report.violations) {
        const dsl::Term& term = prior.block(v.block)->terms()[static_cast<std::size_t>(v.term)];
        fmt::print(stderr,
                   "priormap: warning: {}:{}: '{}' ({}) is not pose-independent: {} becomes {} "
                   "when the map moves by "
                   "dx={:.3f}, dy={:.3f}, dtheta={:.3f}; the degrees-of-freedom analysis assumes "
                   "pose independence "
                   "(paper Def. 3)\n",
                   term.loc.file_name(), term.loc.line, term.source, dsl::ToString(v.block),
                   v.value_before, v.value_after, v.dx, v.dy, v.dtheta);
      }
      fmt::print("  pose independence: {} term(s) changed under rigid motions (warnings above)\n",
                 report.violations.size());
    }
    if (report.undefined_evaluations > 0)
      fmt::print(
          "  pose independence: where defined only: {} term evaluation(s) were NaN or infinite "
          "both before and after the motion, and test nothing\n",
          report.undefined_evaluations);
  }
}

const dsl::CompiledBlock& RequireBlock(const dsl::CompiledPrior& prior, const std::string& name) {
  for (int b = 0; b < dsl::kNumBlockKinds; ++b) {
    const auto kind = static_cast<dsl::BlockKind>(b);
    if (name != dsl::ToString(kind)) continue;
    if (!prior.block(kind))
      throw UserError(
          fmt::format("--block {}: the prior '{}' has no such block", name, prior.name()));
    return *prior.block(kind);
  }
  throw UserError(fmt::format(
      "--block: expected same_region, different_region or different_surface, got '{}'", name));
}

void Show(const PriorOptions& o) {
  const dsl::CompiledPrior prior = Load(o);
  for (int b = 0; b < dsl::kNumBlockKinds; ++b) {
    const dsl::CompiledBlock* block = prior.block(static_cast<dsl::BlockKind>(b));
    if (!block) continue;
    fmt::print("{}, priorlet {}:\n", prior.name(), dsl::ToString(block->kind()));
    for (int t = 0; t < block->num_terms(); ++t) {
      const dsl::Term& term = block->terms()[static_cast<std::size_t>(t)];
      std::string role = dsl::ToString(term.kind);
      if (term.disjunction >= 0)
        role += fmt::format(", disjunction {} branch {}", term.disjunction + 1, term.branch + 1);
      if (term.entries > 1) role += fmt::format(", entry {} of {}", term.entry + 1, term.entries);
      const char* symbol = term.kind == dsl::TermKind::kEquality     ? "f"
                           : term.kind == dsl::TermKind::kInequality ? "g"
                                                                     : "h";
      fmt::print("  term {} ({}; {}:{}: {})\n", t + 1, role, term.loc.file_name(), term.loc.line,
                 term.source);
      fmt::print("    {} = {}\n", symbol, block->TermExpression(t));
      if (!o.derivatives) continue;
      for (int v = 0; v < block->num_variables(); ++v) {
        const std::string d = block->DerivativeExpression(t, v);
        if (d != "0") fmt::print("    d{}/d{} = {}\n", symbol, block->VariableName(v), d);
      }
    }
    const auto lengths = block->TapeLengths();
    fmt::print("  tape: {} instructions for values, {} with gradients, {} with Hessians\n",
               lengths[0], lengths[1], lengths[2]);
  }
}

// "rho_1=1.5,alpha_1=0.2,..." -> name -> value
std::map<std::string, double> ParseAssignments(const std::string& text) {
  std::map<std::string, double> values;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    const std::size_t eq = item.find('=');
    double value = 0.0;
    const char* first = item.data() + (eq == std::string::npos ? 0 : eq + 1);
    const auto [ptr, ec] = std::from_chars(first, item.data() + item.size(), value);
    if (eq == std::string::npos || eq == 0 ||
        (ec != std::errc() && ec != std::errc::result_out_of_range) ||
        ptr != item.data() + item.size()) {
      throw UserError(
          fmt::format("--at: expected name=value pairs separated by commas, got '{}'", item));
    }
    // from_chars leaves `value` unset out of range; strtod tells an overflow (it gives HUGE_VAL)
    // from an underflow (0 or a subnormal), in the C locale priormap never changes.
    const bool out_of_range = ec == std::errc::result_out_of_range;
    if (out_of_range) value = std::strtod(first, nullptr);
    if (out_of_range && std::isinf(value)) {
      throw UserError(fmt::format("--at: {} overflows: above the largest number, {}", item,
                                  std::numeric_limits<double>::max()));
    }
    if (!std::isfinite(value))
      throw UserError(fmt::format("--at: {} is not a finite number", item));
    // As in a prior's literals: below the normal range a value keeps only some of its digits (or
    // none: 1e-330 would be evaluated at 0), and no range or angle is that small.
    if (out_of_range || (value != 0.0 && !std::isnormal(value))) {
      throw UserError(fmt::format(
          "--at: {} underflows: below the smallest normal magnitude, {} (write 0 for zero)", item,
          std::numeric_limits<double>::min()));
    }
    // A repeated name is a typo for another one: taking either value would hide it.
    if (!values.emplace(item.substr(0, eq), value).second)
      throw UserError(fmt::format("--at: {} is given twice", item.substr(0, eq)));
    start = end + 1;
  }
  return values;
}

void Eval(const PriorOptions& o) {
  const dsl::CompiledPrior prior = Load(o);
  const dsl::CompiledBlock& block = RequireBlock(prior, o.block);
  std::map<std::string, double> given = ParseAssignments(o.at);
  const int k = prior.order(), nv = block.num_variables();
  std::vector<double> x(static_cast<std::size_t>(nv)), phi(static_cast<std::size_t>(k));
  const auto take = [&](const std::string& name) {
    const auto it = given.find(name);
    if (it == given.end()) throw UserError(fmt::format("--at: missing a value for {}", name));
    const double v = it->second;
    given.erase(it);
    return v;
  };
  for (int v = 0; v < nv; ++v) x[static_cast<std::size_t>(v)] = take(block.VariableName(v));
  for (int i = 0; i < k; ++i) phi[static_cast<std::size_t>(i)] = take(fmt::format("phi_{}", i + 1));
  if (!given.empty()) {
    throw UserError(fmt::format("--at: '{}' is not a variable of this prior (order {})",
                                given.begin()->first, k));
  }
  const std::size_t nt = static_cast<std::size_t>(block.num_terms());
  std::vector<double> values(nt), gradients(nt * x.size()), hessians(nt * x.size() * x.size());
  dsl::BlockEvaluator evaluator(block);
  evaluator.Evaluate(x, phi, values.data(), gradients.data(), hessians.data());
  std::vector<std::string> names;
  for (int v = 0; v < nv; ++v) names.push_back(block.VariableName(v));
  for (std::size_t t = 0; t < nt; ++t) {
    const dsl::Term& term = block.terms()[t];
    fmt::print(
        "term {} ({}: {})\n  value: {}\n  gradient [{}]:\n    {}\n  Hessian:\n", t + 1,
        dsl::ToString(term.kind), term.source, values[t], fmt::join(names, ", "),
        fmt::join(std::vector<double>(gradients.begin() + static_cast<long>(t * x.size()),
                                      gradients.begin() + static_cast<long>((t + 1) * x.size())),
                  " "));
    for (std::size_t i = 0; i < x.size(); ++i) {
      const auto row = hessians.begin() + static_cast<long>(t * x.size() * x.size() + i * x.size());
      fmt::print("    {}\n",
                 fmt::join(std::vector<double>(row, row + static_cast<long>(x.size())), " "));
    }
  }
}

}  // namespace

void AddPriorCommand(CLI::App& app) {
  auto o = std::make_shared<PriorOptions>();
  CLI::App* prior = app.add_subcommand(
      "prior", "List, check, show and evaluate environment priors (priorlet files)");
  prior->require_subcommand(1);
  // Its subcommands (made below) inherit this: `prior check FILE --prior-path DIR` passes the
  // option up to `prior`, as users write it.
  prior->fallthrough();
  prior
      ->add_option("--prior-path", o->prior_path,
                   "Directory searched for priors by name (repeatable; before PRIORMAP_PRIOR_PATH "
                   "and the built-ins)")
      ->check(CLI::ExistingDirectory);

  prior
      ->add_subcommand("list",
                       "The priors that can be named: the built-in library and --prior-path")
      ->callback([o] { List(*o); });

  CLI::App* check = prior->add_subcommand("check", "Check a prior and summarise it");
  check->add_option("prior", o->prior, "A prior file, or the name of a prior")->required();
  check->add_flag(
      "--pose-independence", o->pose_independence,
      "Also test numerically that the prior does not depend on the map's pose (paper Def. 3)");
  check->add_option("--seed", o->seed, "Seed of the random configurations")
      ->transform(SeedValue())
      ->capture_default_str();
  check->callback([o] { Check(*o); });

  CLI::App* show = prior->add_subcommand(
      "show", "Print each term as compiled (simplified), optionally its derivatives");
  show->add_option("prior", o->prior, "A prior file, or the name of a prior")->required();
  show->add_flag("--derivatives", o->derivatives,
                 "Also print the simplified symbolic gradient of each term");
  show->callback([o] { Show(*o); });

  CLI::App* eval =
      prior->add_subcommand("eval", "Evaluate a block's terms, gradients and Hessians at a point");
  eval->add_option("prior", o->prior, "A prior file, or the name of a prior")->required();
  eval->add_option("--block", o->block, "same_region, different_region or different_surface")
      ->check(CLI::Validator(
          [](std::string& name) -> std::string {
            for (int b = 0; b < dsl::kNumBlockKinds; ++b)
              if (name == dsl::ToString(static_cast<dsl::BlockKind>(b))) return {};
            return fmt::format(
                "expected same_region, different_region or different_surface, got '{}'", name);
          },
          ""))
      ->capture_default_str();
  // Its form here, before the prior is loaded; which names it must give, against the prior.
  eval->add_option("--at", o->at, "Values: rho_1=...,alpha_1=...,phi_1=...,... for i = 1..order")
      ->required()
      ->check(ParsedBy("--at", ParseAssignments));
  eval->callback([o] { Eval(*o); });
}

}  // namespace priormap::app
