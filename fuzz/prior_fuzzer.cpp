// libFuzzer harness for the priorlet language: lexer, parser, checks, inheritance (resolved
// against the built-in library), symbolic differentiation, tape compilation and evaluation.
// Besides crashes, hangs and sanitizer reports it checks that
//  - a rejected text gets exactly one diagnostic, located in the text (or in a built-in parent),
//    and a syntax error is the same whether found by ParsePrior or by CompileText;
//  - every statement printed back (ToSource) parses to the same printed text;
//  - a compiled prior's blocks evaluate at a fixed point with outputs of the documented sizes:
//    values, gradients and symmetric Hessians; a values-only call, a repeated call and a batch of
//    points agree with the full call; gradients are zero for variables a block does not use.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/dsl/parse.hpp>
#include <priormap/dsl/prior.hpp>
#include <priormap/dsl/prior_library.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;

namespace {

namespace dsl = priormap::dsl;

// A directory that does not exist: `specializes:` then resolves in the built-in library only,
// the same on every machine and without reading the disk per input.
constexpr const char* kPath = "/nonexistent-priormap-fuzz/fuzz.prior";

// The lines of the text as diagnostics count them: "\n", "\r\n" and a lone "\r" each end one,
// and so does a run of CRs before an LF ("\r\r\n"); CRs that no LF follows each end one (a text
// ending in a line break has an empty last line). Written apart from the lexer's FindLineEnd, to
// check it.
std::vector<std::string_view> Lines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\r' && text[i] != '\n') continue;
    lines.push_back(text.substr(start, i - start));
    std::size_t run_end = i;
    while (run_end < text.size() && text[run_end] == '\r') ++run_end;
    if (run_end < text.size() && text[run_end] == '\n') {
      i = run_end;  // the CRs and the LF: one line end
    } else {
      for (std::size_t cr = i + 1; cr < run_end; ++cr) lines.emplace_back();  // blank lines
      i = run_end - 1;
    }
    start = i + 1;
  }
  lines.push_back(text.substr(start));
  return lines;
}

// Characters of `line`: UTF-8 continuation bytes do not start one.
int Characters(std::string_view line) {
  return static_cast<int>(std::count_if(line.begin(), line.end(), [](char c) {
    return (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  }));
}

void CheckLocated(const priormap::Diagnostic& d, std::string_view text) {
  Check(!d.message.empty(), "a diagnostic has a message", d.ToString());
  if (d.file == kPath) {
    const std::vector<std::string_view> lines = Lines(text);
    Check(d.line >= 1 && static_cast<std::size_t>(d.line) <= lines.size(),
          "a diagnostic's line is in the text", d.ToString());
    Check(d.col >= 1 && d.col <= Characters(lines[static_cast<std::size_t>(d.line) - 1]) + 1,
          "a diagnostic's column is in its line", d.ToString());
  } else {
    Check(d.file.rfind("<builtin>/", 0) == 0, "a diagnostic names the text or a built-in parent",
          d.ToString());
    Check(d.line >= 1 && d.col >= 1, "a diagnostic in a parent is located", d.ToString());
  }
}

bool Same(const priormap::Diagnostic& a, const priormap::Diagnostic& b) {
  return a.file == b.file && a.line == b.line && a.col == b.col && a.message == b.message;
}

// Equal, both NaN, or equal up to rounding (a batch may schedule the same operations differently).
bool Close(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  if (a == b) return true;
  return std::abs(a - b) <= 1e-12 * std::max({1.0, std::abs(a), std::abs(b)});
}

// Every statement printed back parses, as a statement of the same kind, to the same printed text.
void CheckRoundTrip(const dsl::PriorFile& file) {
  std::vector<const dsl::Statement*> statements;
  for (const dsl::Statement& s : file.definitions) statements.push_back(&s);
  for (const dsl::Block& b : file.blocks) {
    for (const dsl::Statement& s : b.statements) statements.push_back(&s);
  }
  for (const dsl::Statement* s : statements) {
    const std::string printed = dsl::ToSource(*s);
    const priormap::Result<dsl::PriorFile> again = dsl::ParsePrior(
        "name: R\norder: 1\npriorlet same_region:\n  " + printed + "\n", "again.prior");
    Check(again.ok(), "a printed statement parses",
          again.ok() ? printed : printed + "\n" + again.error());
    const auto& block = again.value().blocks;
    Check(block.size() == 1 && block[0].statements.size() == 1,
          "a printed statement is one statement", printed);
    const dsl::Statement& reparsed = block[0].statements[0];
    Check(reparsed.kind == s->kind, "a printed statement keeps its kind", printed);
    Check(dsl::ToSource(reparsed) == printed, "printing is a fixpoint after one round", printed);
  }
}

// The fixed point the blocks are evaluated at: plausible ranges, normals and beam angles.
void EvaluateBlock(const dsl::CompiledBlock& block, int order) {
  Check(block.order() == order, "a block has the prior's order");
  const std::size_t k = static_cast<std::size_t>(order);
  const std::size_t nv = static_cast<std::size_t>(block.num_variables());
  const std::size_t nt = static_cast<std::size_t>(block.num_terms());
  Check(nv == 2 * k, "x is (rho_1..rho_k, alpha_1..alpha_k)");
  Check(block.terms().size() == nt, "one Term per term");
  std::vector<double> x(nv), phi(k);
  for (std::size_t i = 0; i < k; ++i) {
    x[i] = 1.0 + 0.25 * static_cast<double>(i);     // rho_i
    x[k + i] = 0.3 + 0.1 * static_cast<double>(i);  // alpha_i
    phi[i] = -0.5 + 0.05 * static_cast<double>(i);  // phi_i
  }
  // Each output with a guard entry after its end, which must stay untouched.
  constexpr double kGuard = -12345.678;
  std::vector<double> values(nt + 1, kGuard), gradients(nt * nv + 1, kGuard),
      hessians(nt * nv * nv + 1, kGuard);
  dsl::BlockEvaluator evaluator(block);
  evaluator.Evaluate(x, phi, values.data(), gradients.data(), hessians.data());
  Check(values[nt] == kGuard && gradients[nt * nv] == kGuard && hessians[nt * nv * nv] == kGuard,
        "Evaluate writes within the documented sizes");
  for (std::size_t t = 0; t < nt; ++t) {
    for (std::size_t i = 0; i < nv; ++i) {
      for (std::size_t j = 0; j < nv; ++j) {
        const double hij = hessians[(t * nv + i) * nv + j], hji = hessians[(t * nv + j) * nv + i];
        Check(hij == hji || (std::isnan(hij) && std::isnan(hji)), "Hessians are symmetric");
      }
    }
  }
  // Variables no term depends on have zero derivatives.
  const std::vector<std::string>& used = block.summary().variables;
  for (std::size_t v = 0; v < nv; ++v) {
    if (std::find(used.begin(), used.end(), block.VariableName(static_cast<int>(v))) != used.end())
      continue;
    for (std::size_t t = 0; t < nt; ++t) {
      Check(gradients[t * nv + v] == 0.0, "no derivative by an unused variable",
            block.VariableName(static_cast<int>(v)));
    }
  }

  // Values only, and again (phi unchanged: the cached parameter part), agree with the full call.
  std::vector<double> again(nt + 1, kGuard);
  evaluator.Evaluate(x, phi, again.data());
  Check(again[nt] == kGuard, "a values-only call writes num_terms values");
  for (std::size_t t = 0; t < nt; ++t)
    Check(Close(again[t], values[t]), "values-only evaluation agrees");

  // A batch of three points, the fixed one in the middle, agrees with the single call.
  constexpr std::size_t kPoints = 3;
  std::vector<double> xs(kPoints * nv), phis(kPoints * k);
  for (std::size_t p = 0; p < kPoints; ++p) {
    for (std::size_t i = 0; i < nv; ++i)
      xs[p * nv + i] = x[i] + 0.01 * (static_cast<double>(p) - 1.0);
    for (std::size_t i = 0; i < k; ++i) phis[p * k + i] = phi[i];
  }
  std::vector<double> batch_values(kPoints * nt + 1, kGuard),
      batch_gradients(kPoints * nt * nv + 1, kGuard),
      batch_hessians(kPoints * nt * nv * nv + 1, kGuard);
  evaluator.EvaluateBatch(kPoints, xs, phis, batch_values.data(), batch_gradients.data(),
                          batch_hessians.data());
  Check(batch_values[kPoints * nt] == kGuard && batch_gradients[kPoints * nt * nv] == kGuard &&
            batch_hessians[kPoints * nt * nv * nv] == kGuard,
        "EvaluateBatch writes within the documented sizes");
  for (std::size_t t = 0; t < nt; ++t)
    Check(Close(batch_values[nt + t], values[t]), "batch values agree");
  for (std::size_t i = 0; i < nt * nv; ++i)
    Check(Close(batch_gradients[nt * nv + i], gradients[i]), "batch gradients agree");
  for (std::size_t i = 0; i < nt * nv * nv; ++i) {
    Check(Close(batch_hessians[nt * nv * nv + i], hessians[i]), "batch Hessians agree");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  static const dsl::PriorLibrary library;  // the built-in priors only

  const priormap::Result<dsl::PriorFile> parsed = dsl::ParsePrior(text, kPath);
  const priormap::Result<dsl::CompiledPrior> compiled = library.CompileText(text, kPath);
  if (!parsed.ok()) {
    Check(parsed.diagnostics().size() == 1, "a syntax error is one diagnostic", parsed.error());
    CheckLocated(parsed.diagnostics()[0], text);
    Check(!compiled.ok() && compiled.diagnostics().size() == 1 &&
              Same(compiled.diagnostics()[0], parsed.diagnostics()[0]),
          "CompileText reports the syntax error ParsePrior finds", parsed.error());
    return 0;
  }
  CheckRoundTrip(parsed.value());
  if (!compiled.ok()) {
    Check(compiled.diagnostics().size() == 1, "a failed compilation is one diagnostic",
          compiled.error());
    CheckLocated(compiled.diagnostics()[0], text);
    return 0;
  }

  const dsl::CompiledPrior& prior = compiled.value();
  Check(prior.order() >= 1 && prior.order() <= 16, "the order is 1..16");
  Check(!(prior.max_curvature() < 0.0), "max_curvature is not negative");
  Check(!prior.chain().empty() && prior.chain().front().path == kPath,
        "the chain starts with the text itself");
  for (int kind = 0; kind < dsl::kNumBlockKinds; ++kind) {
    if (const dsl::CompiledBlock* block = prior.block(static_cast<dsl::BlockKind>(kind))) {
      Check(block->kind() == static_cast<dsl::BlockKind>(kind), "a block is stored under its kind");
      EvaluateBlock(*block, prior.order());
    }
  }
  return 0;
}
