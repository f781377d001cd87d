#!/usr/bin/env bash
# A subset of the test suite under AddressSanitizer + UndefinedBehaviorSanitizer (the `asan`
# preset): the readers and writers, the geometry, the priorlet language, the grids, the PRF's
# colorings, sweeps and incremental data terms, and the SLAM files. The engines' long numerical
# tests and the app's are left out: the whole suite under the sanitizers would not fit CI's time.
# Called by scripts/test.sh; extra arguments go to every test binary (e.g. --gtest_filter=...).
set -euo pipefail
cd "$(dirname "$0")/.."
suites=(core_tests dsl_tests grid_tests prf_tests slam_io_tests)
cmake --preset asan -DPRIORMAP_WARNINGS_AS_ERRORS=ON >/dev/null
cmake --build --preset asan --target "${suites[@]}"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export RC_PARAMS=seed=20261121  # the property tests' fixed seed, as in ctest
for suite in "${suites[@]}"; do
  echo "asan: $suite"
  started=$SECONDS
  # A bound, so that a hang under the sanitizers names its suite instead of using up CI's time.
  timeout 1200 "build/asan/tests/$suite" --gtest_brief=1 "$@" ||
    { echo "asan: $suite failed or ran over 20 minutes" >&2; exit 1; }
  echo "asan: $suite took $((SECONDS - started)) s"
done
