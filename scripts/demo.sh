#!/usr/bin/env bash
# Quick start 1/2: install dependencies, build the priormap app (and the Python module), run
# `priormap demo`.
# Extra arguments are passed to `priormap demo` (try --help).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target priormap _priormap  # the app and the Python module
exec build/release/bin/priormap demo "$@"
