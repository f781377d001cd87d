// libFuzzer harness for the coloring part of PRF checkpoints (Coloring::Load), without the
// checksum that guards whole files, so that damaged or hostile data reach the loader: it must
// refuse them with BinaryFormatError or give a valid coloring, which saves to bytes that load
// back to the same coloring.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <priormap/core/binary_io.hpp>
#include <priormap/prf/coloring.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  // The window and cell of the seed corpus (fuzz/corpus/prf_coloring_fuzzer).
  const priormap::prf::Window window{priormap::Vec2::Zero(), priormap::Vec2::Ones()};
  priormap::BinaryReader in(bytes, "fuzz");
  std::optional<priormap::prf::Coloring> coloring;
  try {
    coloring.emplace(priormap::prf::Coloring::Load(in, window, 0.125));
  } catch (const priormap::BinaryFormatError&) {
    return 0;
  }
  Check(!coloring->FindInvariantViolation(1e-6), "a loaded coloring is valid");
  priormap::BinaryWriter out;
  coloring->Save(out);
  priormap::BinaryReader again(out.bytes(), "again");
  try {
    const priormap::prf::Coloring reloaded = priormap::prf::Coloring::Load(again, window, 0.125);
    priormap::BinaryWriter out_again;
    reloaded.Save(out_again);
    Check(again.AtEnd() && out_again.bytes() == out.bytes(), "a saved coloring loads the same");
  } catch (const priormap::BinaryFormatError& e) {
    Check(false, "a saved coloring loads again", e.what());
  }
  return 0;
}
