#!/usr/bin/env bash
# Installs the Debian packages imusysid needs, if any are missing.
# As root it runs apt-get itself; otherwise it prints the exact command to run.
#   scripts/setup.sh              build + test dependencies
#   scripts/setup.sh --with-clang also clang and its sanitizer runtimes (the
#                                 test command's compiler, scripts/test.sh)
#   scripts/setup.sh --with-fuzz  also clang's libFuzzer runtime
#   scripts/setup.sh --with-peers also GNU Octave + octave-ga and SciPy, for
#                                 benchmarks/peers/run_peers.sh
set -euo pipefail

packages=(
  build-essential cmake git ninja-build
  libceres-dev libeigen3-dev libgflags-dev libgoogle-glog-dev
  libgtest-dev libgmock-dev libbenchmark-dev nlohmann-json3-dev
  gnuplot-nox
  # The Python module (python/) and its tests, and imusysid.fleet on Dask.
  pybind11-dev python3-dev python3-numpy python3-pytest
  python3-distributed python3-pandas python3-tqdm
  # The report page's test renders it in a real browser (headless).
  chromium
)
for arg in "$@"; do
  case "$arg" in
    --with-clang|--with-fuzz) packages+=(clang libclang-rt-dev) ;;
    --with-peers) packages+=(octave octave-ga python3 python3-numpy python3-scipy) ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

cmd=(apt-get install -y --no-install-recommends "${missing[@]}")
if [ "$(id -u)" -ne 0 ]; then
  echo "setup: missing packages: ${missing[*]}" >&2
  echo "setup: run:  sudo apt-get update && sudo ${cmd[*]}" >&2
  exit 1
fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
"${cmd[@]}"
