// priormap.infer_scan, priormap.list_priors, priormap.load_prior / compile_prior and the Prior
// class: the priorlet engine and the prior language from Python.
#include <cmath>
#include <limits>
#include <memory>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/map_scan_json.hpp>
#include <priormap/priorlets/posterior.hpp>

#include "bindings.hpp"
#include "convert.hpp"

namespace priormap::python {
namespace {

template <typename T>
T ValueOrRaise(Result<T> result) {
  if (!result) throw std::invalid_argument(result.error());
  return std::move(result).value();
}

// Paths from Python: str or any os.PathLike (pathlib.Path).
using Paths = std::vector<std::filesystem::path>;

dsl::PriorLibrary Library(const Paths& prior_path) {
  return dsl::PriorLibrary::WithEnvironment({prior_path.begin(), prior_path.end()});
}

// "file:line:col: message", as the CLI prints a prior's warnings.
std::string WarningText(const Diagnostic& warning) {
  return fmt::format("{}: {}", warning.Location(), warning.message);
}

// A prior that compiles with warnings (a constraint that always holds) is still usable, so the
// warnings go through Python's warnings module, which a caller can filter or turn into errors,
// rather than being dropped as they were, or printed to a stderr a notebook may not show.
dsl::CompiledPrior WarnedAbout(dsl::CompiledPrior prior) {
  for (const Diagnostic& warning : prior.warnings()) {
    const std::string text = WarningText(warning);
    // With the warning filtered into an error, the exception is Python's and goes on up.
    if (PyErr_WarnEx(PyExc_UserWarning, text.c_str(), 1) != 0) throw py::error_already_set();
  }
  return prior;
}

dsl::BlockKind BlockKindOf(const std::string& name) {
  for (int k = 0; k < dsl::kNumBlockKinds; ++k)
    if (name == dsl::ToString(static_cast<dsl::BlockKind>(k)))
      return static_cast<dsl::BlockKind>(k);
  throw std::invalid_argument(fmt::format(
      "unknown block '{}' (expected same_region, different_region or different_surface)", name));
}

// A compiled prior, shared so that Python copies are cheap.
struct Prior {
  std::shared_ptr<const dsl::CompiledPrior> compiled;

  [[nodiscard]] const dsl::CompiledBlock& Block(const std::string& name) const {
    const dsl::CompiledBlock* block = compiled->block(BlockKindOf(name));
    if (block == nullptr)
      throw std::invalid_argument(
          fmt::format("the prior '{}' has no {} block", compiled->name(), name));
    return *block;
  }

  [[nodiscard]] std::vector<std::string> Blocks() const {
    std::vector<std::string> names;
    for (int k = 0; k < dsl::kNumBlockKinds; ++k)
      if (compiled->block(static_cast<dsl::BlockKind>(k)) != nullptr)
        names.emplace_back(dsl::ToString(static_cast<dsl::BlockKind>(k)));
    return names;
  }

  [[nodiscard]] std::vector<std::string> Terms(const std::string& block_name) const {
    const dsl::CompiledBlock& block = Block(block_name);
    std::vector<std::string> terms;
    for (int t = 0; t < block.num_terms(); ++t) terms.push_back(block.TermExpression(t));
    return terms;
  }

  // Values (terms,) and gradients (terms, 2k) at x = (rho_1..rho_k, alpha_1..alpha_k), phi (k,).
  [[nodiscard]] py::dict Evaluate(const std::string& block_name, const std::vector<double>& x,
                                  const std::vector<double>& phi) const {
    const dsl::CompiledBlock& block = Block(block_name);
    if (static_cast<int>(x.size()) != block.num_variables() ||
        static_cast<int>(phi.size()) != block.order())
      throw std::invalid_argument(fmt::format(
          "{} block of order {}: x needs {} values (rho_1..rho_k, alpha_1..alpha_k), phi {}",
          block_name, block.order(), block.num_variables(), block.order()));
    const auto terms = static_cast<py::ssize_t>(block.num_terms());
    const auto variables = static_cast<py::ssize_t>(block.num_variables());
    py::array_t<double> values(terms);
    py::array_t<double> gradients({terms, variables});
    dsl::BlockEvaluator evaluator(block);
    evaluator.Evaluate(x, phi, values.mutable_data(), gradients.mutable_data());
    py::dict out;
    out["values"] = values;
    out["gradients"] = gradients;
    std::vector<std::string> names;
    for (int v = 0; v < block.num_variables(); ++v) names.push_back(block.VariableName(v));
    out["variables"] = names;
    return out;
  }
};

py::dict InferScan(const Doubles& ranges, const Doubles& angles,
                   const std::filesystem::path& prior_name, double sigma, double max_range,
                   double min_range, double beta, int eigenvariations, const Paths& prior_path) {
  if (ranges.ndim() != 1) throw std::invalid_argument("ranges must be one scan: shape (m,)");
  if (ranges.shape(0) == 0) throw std::invalid_argument("ranges is empty: a scan needs readings");
  // The bounds of `priormap scan --beta` and `--eigenvariations`.
  if (!(beta >= 1e-6 && beta <= 0.999999))
    throw std::invalid_argument(fmt::format("beta must be in [1e-6, 0.999999], got {}", beta));
  if (eigenvariations < 0 || eigenvariations > 1000)
    throw std::invalid_argument(
        fmt::format("eigenvariations must be in [0, 1000], got {}", eigenvariations));
  py::array_t<double> poses({py::ssize_t{1}, py::ssize_t{3}});
  std::fill(poses.mutable_data(), poses.mutable_data() + 3, 0.0);
  py::array_t<double> ranges_2d({py::ssize_t{1}, ranges.shape(0)});
  std::copy(ranges.data(), ranges.data() + ranges.shape(0), ranges_2d.mutable_data());
  const Log log =
      LogFromArrays(poses, ranges_2d, angles, max_range, min_range, sigma, /*one_scan=*/true);
  const dsl::CompiledPrior prior =
      WarnedAbout(ValueOrRaise(Library(prior_path).Load(prior_name.string())));
  priorlets::EngineOptions engine;
  engine.beta = beta;
  priorlets::PosteriorOptions posterior_options;
  posterior_options.eigenvariations = eigenvariations;
  std::string json;
  {
    const py::gil_scoped_release release;  // the solve is long and touches no Python object
    const Scan& scan = log.scans.front();
    const priorlets::MapScan map = priorlets::EstimateMapScan(scan, prior, engine);
    const priorlets::Posterior posterior =
        priorlets::AnalysePosterior(scan, prior, map, posterior_options);
    json = priorlets::MapScanToJson(map, {0, prior.name(), "python"}, &posterior);
  }
  return JsonToPython(nlohmann::json::parse(json)).cast<py::dict>();
}

}  // namespace

void BindPriorlets(py::module_& m) {
  py::class_<Prior>(m, "Prior",
                    "A compiled environment prior (the prior language, docs/priorlet-language.md)")
      .def_property_readonly(
          "name", [](const Prior& p) { return p.compiled->name(); },
          "The prior's name (its 'name:' header)")
      .def_property_readonly(
          "order", [](const Prior& p) { return p.compiled->order(); },
          "k: how many consecutive readings a priorlet relates")
      .def_property_readonly(
          "max_curvature", [](const Prior& p) { return p.compiled->max_curvature(); },
          "The largest curvature of any surface, 1/m (0: straight walls only); inf when the "
          "prior gives none")
      .def_property_readonly("blocks", &Prior::Blocks, "The topology cases the prior constrains")
      .def_property_readonly(
          "warnings",
          [](const Prior& p) {
            std::vector<std::string> texts;
            for (const Diagnostic& warning : p.compiled->warnings())
              texts.push_back(WarningText(warning));
            return texts;
          },
          "What compiled but looks wrong ('file:line:col: message'), e.g. a constraint that "
          "uses no variable and always holds; also issued as UserWarning when the prior is loaded")
      .def("terms", &Prior::Terms, py::arg("block"),
           "The compiled terms of a block, as simplified expressions")
      .def("evaluate", &Prior::Evaluate, py::arg("block"), py::arg("x"), py::arg("phi"),
           "The block's term values and gradients at x = (rho_1..rho_k, alpha_1..alpha_k) and "
           "beam angles phi (k): dict of 'values', 'gradients' (terms x 2k), 'variables'")
      .def("__repr__", [](const Prior& p) {
        return fmt::format("<priormap.Prior '{}' of order {}>", p.compiled->name(),
                           p.compiled->order());
      });

  m.def(
      "load_prior",
      [](const std::filesystem::path& name_or_file, const Paths& prior_path) {
        return Prior{std::make_shared<const dsl::CompiledPrior>(
            WarnedAbout(ValueOrRaise(Library(prior_path).Load(name_or_file.string()))))};
      },
      py::arg("name_or_file"), py::arg("prior_path") = Paths{},
      "A prior of the library by name ('rectangular', 'Circular prior', ...) or a .prior file "
      "(str or pathlib.Path); prior_path: more directories to search, before "
      "PRIORMAP_PRIOR_PATH and the built-ins. Errors raise ValueError");
  m.def(
      "compile_prior",
      [](const std::string& text, const Paths& prior_path) {
        return Prior{std::make_shared<const dsl::CompiledPrior>(
            WarnedAbout(ValueOrRaise(Library(prior_path).CompileText(text, "<python>"))))};
      },
      py::arg("text"), py::arg("prior_path") = Paths{},
      "Compiles prior-language source text; errors raise ValueError with "
      "'<python>:line:col: error: ...'. Parents named by 'specializes:' come from prior_path "
      "and the library, never from the current directory");
  m.def(
      "list_priors",
      [](const Paths& prior_path) {
        py::list out;
        for (const dsl::PriorListing& p : Library(prior_path).List()) {
          py::dict d;
          d["name"] = p.name;
          d["path"] = p.path;
          d["description"] = p.description;
          d["builtin"] = p.builtin;
          out.append(d);
        }
        return out;
      },
      py::arg("prior_path") = Paths{},
      "The priors of the library, as dicts of 'name', 'path', 'description' and 'builtin'");
  m.def("infer_scan", &InferScan, py::arg("ranges"), py::arg("angles"),
        py::arg("prior") = "polygonal", py::arg("sigma") = 0.01,
        py::arg("max_range") = std::numeric_limits<double>::infinity(), py::arg("min_range") = 0.0,
        py::arg("beta") = 0.95, py::arg("eigenvariations") = 3, py::arg("prior_path") = Paths{},
        "MAP scan under a prior (priorlets): one scan's ranges and angles (numpy, radians) in; "
        "a dict out with numpy arrays 'rho' (corrected ranges), 'alpha' (normal angles), "
        "'inmodel' (False: outlier), 'posterior_std', the 'regions', 'surfaces', 'dof' and "
        "eigenvariations (the fields of `priormap scan`'s JSON)");
}

}  // namespace priormap::python
