#!/usr/bin/env bash
# Quick start 2/2: install dependencies, build everything, run the whole test suite (ctest), then
# the parsers' fuzz harnesses for a bounded time, then a subset of the suite under ASan + UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh --tests
# The suite's builds treat warnings as errors: on Debian 12's compilers the build is warning-free,
# and this keeps it so. The option is off by default, so that another compiler's new warnings do
# not stop a user's own build.
cmake --preset release -DPRIORMAP_WARNINGS_AS_ERRORS=ON >/dev/null
cmake --build --preset release
ctest --preset release "$@"
echo "test.sh: release build and suite done at ${SECONDS} s"
# The parsers' libFuzzer harnesses, each for a bounded time on its seed corpus (clang, ASan + UBSan).
cmake --preset fuzz -DPRIORMAP_WARNINGS_AS_ERRORS=ON >/dev/null
cmake --build --preset fuzz
ctest --preset fuzz
echo "test.sh: fuzzers done at ${SECONDS} s"
# The readers, geometry, language, grids, PRF and SLAM files under AddressSanitizer + UBSan.
scripts/asan-tests.sh
echo "test.sh: ASan subset done at ${SECONDS} s"
