// libFuzzer harness for the gzip container of the files priormap reads (logs may be .gz): the
// input is written to a file (without .gz: the magic bytes decide) and read by both readers,
// detail::ReadWholeFile (libdeflate; ReadLog and the CARMEN reader) and ReadFileText (zlib's
// inflate; every other reader). ReadWholeFile promises ReadFileText's contract, so besides
// crashes and sanitizer reports it checks that
//  - a failure is one diagnostic naming the file, and both readers fail on the same inputs
//    (corrupt or truncated members, bytes after the last member that do not start another),
//    but for one leniency of libdeflate's known upstream (ReadBoth);
//  - both give the same bytes, and bytes that are not gzip data come back unchanged;
//  - what they inflate, written by the writer (WriteTextFileAtomically to a .gz name), reads
//    back the same through both.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/file_io.hpp>

#include "fuzz_check.hpp"
#include "fuzz_scratch.hpp"
#include "gunzip.hpp"  // src/core: ReadWholeFile

using priormap::fuzz::Check;

namespace {

bool StartsGzip(std::string_view bytes) {
  return bytes.starts_with("\x1f\x8b");
}

void CheckFailure(const std::vector<priormap::Diagnostic>& diagnostics, const std::string& name) {
  Check(diagnostics.size() == 1, "a failed read has one diagnostic");
  const priormap::Diagnostic& d = diagnostics.front();
  Check(d.file == name && !d.message.empty(), "a diagnostic names the file and the problem",
        d.ToString());
}

std::string Describe(const priormap::Result<priormap::detail::ByteBuffer>& whole,
                     const priormap::Result<std::string>& text) {
  return "ReadWholeFile: " + (whole.ok() ? std::string("read") : whole.error()) +
         "\nReadFileText: " + (text.ok() ? std::string("read") : text.error());
}

// Both readers of `path`: they agree, and a failure is one diagnostic naming the file.
// Returns whether they read it.
bool ReadBoth(const std::filesystem::path& path, std::string* bytes) {
  const priormap::Result<priormap::detail::ByteBuffer> whole =
      priormap::detail::ReadWholeFile(path);
  const priormap::Result<std::string> text = priormap::ReadFileText(path);
  if (!whole.ok()) CheckFailure(whole.diagnostics(), path.string());
  if (!text.ok()) CheckFailure(text.diagnostics(), path.string());
  // The one disagreement known upstream, not ours to mend: libdeflate 1.14 (Debian 12's)
  // inflates some members that zlib refuses as "invalid literal/length code" (reported as
  // ebiggers/libdeflate#288; e.g. the seed libdeflate_lenient_literal_length.gz). Both check the
  // member's CRC and size, so what libdeflate gives is what was compressed.
  if (whole.ok() && !text.ok() &&
      text.error().find("(invalid literal/length code)") != std::string::npos)
    return false;
  Check(whole.ok() == text.ok(), "libdeflate and zlib refuse the same data", Describe(whole, text));
  if (!whole.ok()) return false;
  Check(whole.value().view() == text.value(), "libdeflate and zlib inflate the same bytes");
  *bytes = text.value();
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const priormap::fuzz::ScratchDirectory& scratch = priormap::fuzz::Scratch();
  std::string bytes;
  if (!ReadBoth(scratch.Write("input", input), &bytes)) return 0;
  if (!StartsGzip(input)) {
    Check(bytes == input, "data that is not gzip is read unchanged");
    return 0;
  }
  const std::filesystem::path again = scratch.path() / "again.gz";
  priormap::WriteTextFileAtomically(again, bytes);
  std::string bytes_again;
  Check(ReadBoth(again, &bytes_again), "written gzip data is read back");
  Check(bytes_again == bytes, "the round trip through the writer keeps the bytes");
  return 0;
}
