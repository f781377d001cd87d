#!/usr/bin/env bash
# Quick start 2/2: install dependencies, build everything, run the whole test suite (ctest), then
# the parsers' fuzz harnesses for a bounded time, then a subset of the suite under ASan + UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --tests
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release "$@"
# The parsers' libFuzzer harnesses, each for a bounded time on its seed corpus (clang, ASan + UBSan).
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz
ctest --preset fuzz
# The readers, geometry, language, grids, PRF and SLAM files under AddressSanitizer + UBSan.
scripts/asan-tests.sh
