// priormap: 2D mapping with structural prior knowledge. A thin shell: each subcommand parses
// its options, calls the library and reports; errors go to stderr as "priormap: error: ...".
#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace {

// The exit statuses (README, "The command line"): 0 done, 1 an error in the input or the run
// (an option value checked against the input or other options among them), 2 a command line
// that does not parse (CLI11's errors, and the commands' UsageError), 3 an internal error,
// 128 + the signal for a run stopped by SIGINT or SIGTERM.
constexpr int kUsageError = 2;

// One "priormap: error: " prefix per line, so multi-line diagnostics stay greppable.
void PrintError(std::string_view message) {
  std::size_t start = 0;
  while (start <= message.size()) {
    const std::size_t end = std::min(message.find('\n', start), message.size());
    fmt::print(stderr, "priormap: error: {}\n", message.substr(start, end - start));
    start = end + 1;
  }
}

// A signal that ends the process would leave the temporary file of an output being written.
extern "C" void RemoveTemporariesAndDie(int signal) {
  priormap::RemoveTemporaryFilesInProgress();
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

void RemoveTemporariesOnSignals() {
  struct sigaction action {};
  action.sa_handler = RemoveTemporariesAndDie;
  sigemptyset(&action.sa_mask);
  for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction previous {};
    // An ignored signal stays ignored (nohup; a shell's background job and SIGINT).
    if (sigaction(signal, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
    sigaction(signal, &action, nullptr);
  }
}

// Output lost (a full disk, a closed pipe, /dev/full) must not end in a success, so `status`
// 0 becomes 1 when stdout cannot be flushed.
int FlushStandardOutput(int status) {
  errno = 0;
  if (std::fflush(stdout) == 0 && std::ferror(stdout) == 0) return status;
  const int error = errno;
  fmt::print(stderr, "priormap: error: cannot write to standard output: {}\n",
             error != 0 ? std::strerror(error) : "write failed");
  return status == 0 ? 1 : status;
}

// The arguments of the command line that no command knew (a mistyped option, a stray word), as
// CLI11 reports them; none when every argument was known. CLI11 checks the options' values and
// the required options before it looks for those: told first of a missing --out, the user who
// typed --ouput would not learn of the typo.
std::optional<std::string> UnexpectedArguments(const CLI::App& app) {
  const std::vector<std::string> extras = app.remaining(true);
  if (extras.empty()) return std::nullopt;
  // CLI11's words, the arguments in the order given (its own message reverses them).
  return fmt::format("The following argument{} not expected: {}",
                     extras.size() > 1 ? "s were" : " was", fmt::join(extras, " "));
}

}  // namespace

int main(int argc, char** argv) {
  RemoveTemporariesOnSignals();
  CLI::App app{"priormap: 2D robotic mapping with structural prior knowledge", "priormap"};
  app.require_subcommand(1);
  app.fallthrough(false);
  priormap::app::AddAllCommands(app);
  // CLI11 would only say "a subcommand is required"; name the word it did not know.
  if (argc > 1 && argv[1][0] != '-') {
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
      names.push_back(sub->get_name());
    if (std::find(names.begin(), names.end(), argv[1]) == names.end()) {
      PrintError(fmt::format("unknown command '{}' (expected one of: {}); run 'priormap --help'",
                             argv[1], fmt::join(names, ", ")));
      return kUsageError;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return FlushStandardOutput(app.exit(e));
  } catch (const CLI::CallForAllHelp& e) {
    return FlushStandardOutput(app.exit(e));
  } catch (const CLI::CallForVersion& e) {
    return FlushStandardOutput(app.exit(e));
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr,
               "priormap: error: {}\nRun 'priormap --help' or 'priormap <command> --help'.\n",
               UnexpectedArguments(app).value_or(e.what()));
    // Every command line that does not parse exits 2, as an unknown command does above (and
    // getopt tools do): CLI11's own codes (105 for a value out of range, 106 for a missing
    // option, ...) would tell a script nothing a message does not, and look like crashes or
    // signals to a scheduler.
    return kUsageError;
  } catch (const priormap::app::UsageError& e) {
    PrintError(UnexpectedArguments(app).value_or(e.what()));
    return kUsageError;
  } catch (const priormap::app::UserError& e) {
    PrintError(e.what());
    return 1;
  } catch (const priormap::IoError& e) {
    fmt::print(stderr, "priormap: error: {}\n", e.what());
    return 1;
  } catch (const priormap::ContractError& e) {
    fmt::print(stderr, "priormap: internal error (please report): {}\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    fmt::print(stderr, "priormap: error: {}\n", e.what());
    return 1;
  }
  return FlushStandardOutput(0);
}
