#include "testing/process.hpp"

#include <cstdlib>
#include <sys/wait.h>

#include "testing/temp_dir.hpp"

namespace priormap::testing {

std::string ShellQuote(const std::string& s) {
  std::string quoted = "'";
  for (char c : s) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

ProcessResult RunProgram(const std::filesystem::path& program, const std::filesystem::path& work,
                         const std::filesystem::path& io, const std::vector<std::string>& args) {
  // (Appending piecewise: GCC 12 gives a false -Wrestrict for "literal" + std::string&&.)
  std::string command = "cd ";
  command += ShellQuote(work.string());
  command += " && ";
  command += ShellQuote(program.string());
  for (const std::string& arg : args) command.append(" ").append(ShellQuote(arg));
  command.append(" >").append(ShellQuote((io / "stdout").string()));
  command.append(" 2>").append(ShellQuote((io / "stderr").string()));
  const int raw = std::system(command.c_str());
  ProcessResult result;
  result.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = ReadAll(io / "stdout");
  result.err = ReadAll(io / "stderr");
  return result;
}

std::set<std::string> FilesUnder(const std::filesystem::path& dir) {
  std::set<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    files.insert(std::filesystem::relative(entry.path(), dir).string());
  }
  return files;
}

}  // namespace priormap::testing
