#!/usr/bin/env bash
# Installs the Debian 12 packages priormap needs to build, test and benchmark.
# Idempotent: prints nothing and touches nothing when every package is present.
#   --tests      also what only the test suite needs (Chromium, for the demo gallery's browser
#                test)
#   --baselines  also the libraries of the side-by-side baselines in bench/ (MRPT's occupancy
#                grid; about 110 packages, so not part of the quick start)
set -euo pipefail

packages=(
  # toolchain
  g++ make cmake ninja-build pkg-config
  # libraries (all from Debian, see README "Dependencies")
  libeigen3-dev libcli11-dev nlohmann-json3-dev libfmt-dev libcairo2-dev libtbb-dev zlib1g-dev
  # derivative-free maximum likelihood of the sonar model (prf fit-sonar)
  libnlopt-dev
  # whole-buffer gunzip for the log readers (zlib reads them when it is absent)
  libdeflate-dev
  # the Python module (pybind11, NumPy) and its tests (pytest), for the system python3
  pybind11-dev python3-dev python3-numpy python3-pytest
  # a font for figure labels (Cairo's toy text API goes through fontconfig)
  fonts-dejavu-core
  # tests and benchmarks; clang and its runtime for the libFuzzer harnesses
  libgtest-dev libgmock-dev libbenchmark-dev librapidcheck-dev clang libclang-rt-14-dev
  # llvm-symbolizer, without which sanitizer and fuzzer reports show bare addresses
  llvm-14
)

for option in "$@"; do
  case "$option" in
    --tests) packages+=(chromium) ;;
    --baselines) packages+=(libmrpt-maps-dev) ;;
    *)
      echo "install-deps: unknown option '$option' (expected: --tests, --baselines or nothing)" >&2
      exit 2
      ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "installed" ]] || missing+=("$p")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

sudo=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}" >&2
# Through env: sudo resets the environment, and apt would then be free to ask questions.
$sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
  "${missing[@]}" >/dev/null
