#include <algorithm>
#include <atomic>
#include <fstream>
#include <unistd.h>

#include <fmt/format.h>
#include <zlib.h>

#include <priormap/core/file_io.hpp>

namespace priormap {
namespace fs = std::filesystem;
namespace {

bool EndsWithGz(const fs::path& path) {
  return path.extension() == ".gz";
}

fs::path TemporarySibling(const fs::path& path) {
  static std::atomic<unsigned> counter{0};
  const std::string name =
      fmt::format(".{}.tmp-{}-{}", path.filename().string(), ::getpid(), counter++);
  return path.parent_path() / name;
}

}  // namespace

Result<std::string> ReadFileText(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) return Diagnostic{name, 0, 0, "no such file"};
  if (fs::is_directory(path, ec)) return Diagnostic{name, 0, 0, "is a directory, expected a file"};
  // gzread reads plain files unchanged, so one code path serves both.
  gzFile file = gzopen(name.c_str(), "rb");
  if (file == nullptr) return Diagnostic{name, 0, 0, "cannot open file for reading"};
  gzbuffer(file, 1 << 17);
  std::string text;
  std::string chunk(1 << 20, '\0');
  for (;;) {
    const int n = gzread(file, chunk.data(), static_cast<unsigned>(chunk.size()));
    if (n < 0) break;
    text.append(chunk.data(), static_cast<std::size_t>(n));
    if (n == 0) break;
  }
  int error = Z_OK;
  const char* message = gzerror(file, &error);
  const std::string error_text = message ? message : "";
  gzclose(file);
  if (error != Z_OK && error != Z_STREAM_END) {
    return Diagnostic{name, 0, 0, fmt::format("corrupt or truncated gzip data ({})", error_text)};
  }
  return text;
}

void WriteFileAtomically(const fs::path& named, const std::function<void(const fs::path&)>& write) {
  std::error_code ec;
  // A link is written through, to the file it names: renaming over the link itself would
  // replace it by a plain file and leave its target stale.
  fs::path path = named;
  if (fs::is_symlink(named, ec)) {
    path = fs::weakly_canonical(named, ec);
    if (ec) throw IoError(fmt::format("{}: cannot write: {}", named.string(), ec.message()));
  }
  const fs::path directory = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (!fs::is_directory(directory, ec)) {
    if (fs::exists(directory, ec)) {
      throw IoError(fmt::format("{}: cannot write: {} is not a directory", path.string(),
                                directory.string()));
    }
    throw IoError(fmt::format("{}: cannot write: directory {} does not exist", path.string(),
                              directory.string()));
  }
  const fs::path temporary = TemporarySibling(path);
  try {
    write(temporary);
    // A file replaced keeps its permissions (a private log stays private).
    const fs::file_status existing = fs::status(path, ec);
    if (!ec && fs::is_regular_file(existing)) fs::permissions(temporary, existing.permissions());
    fs::rename(temporary, path);
  } catch (const fs::filesystem_error& e) {
    fs::remove(temporary, ec);
    throw IoError(fmt::format("{}: cannot write: {}", path.string(), e.code().message()));
  } catch (...) {
    fs::remove(temporary, ec);
    throw;
  }
}

void WriteTextFileAtomically(const fs::path& path, std::string_view content) {
  WriteFileAtomically(path, [&](const fs::path& temporary) {
    if (EndsWithGz(path)) {
      gzFile file = gzopen(temporary.string().c_str(), "wb");
      if (file == nullptr) throw IoError(fmt::format("{}: cannot open for writing", path.string()));
      const bool ok =
          content.empty() || gzwrite(file, content.data(), static_cast<unsigned>(content.size())) ==
                                 static_cast<int>(content.size());
      if (gzclose(file) != Z_OK || !ok) {
        throw IoError(fmt::format("{}: write failed", path.string()));
      }
      return;
    }
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(fmt::format("{}: cannot open for writing", path.string()));
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.close();
    if (!out) throw IoError(fmt::format("{}: write failed (disk full?)", path.string()));
  });
}

TextPosition PositionOfOffset(std::string_view text, std::size_t offset) {
  TextPosition position;
  offset = std::min(offset, text.size());
  for (std::size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++position.line;
      position.col = 1;
    } else {
      ++position.col;
    }
  }
  return position;
}

bool IsNumberedName(std::string_view name, std::string_view prefix, std::string_view suffix,
                    bool zero_padded) {
  if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) ||
      !name.ends_with(suffix))
    return false;
  const std::string_view number =
      name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  if (!zero_padded && number.size() > 1 && number.front() == '0') return false;
  return std::ranges::all_of(number, [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace priormap
