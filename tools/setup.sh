#!/usr/bin/env bash
# shroudsim set-up on a Debian 12 machine: installs the missing Debian packages (quietly,
# only when something is missing), configures and builds (Release), then
#   tools/setup.sh demo   runs the default case end to end (cases/shrouded_wheel.toml)
#   tools/setup.sh test   runs the whole test suite (ctest)
#   tools/setup.sh build  only installs and builds
# Needs root (or sudo) only when a package is missing. SHROUDSIM_BUILD_DIR (default build)
# names the build folder; SHROUDSIM_CMAKE_ARGS adds configure options (the CI passes
# -DSHROUDSIM_WERROR=ON).
set -euo pipefail

cd "$(dirname "$0")/.."
mode="${1:-build}"
case "$mode" in demo|test|build) ;; *) echo "usage: tools/setup.sh [demo|test|build]" >&2; exit 2 ;; esac

packages=(
  cmake make g++ pkg-config
  libeigen3-dev libspectra-dev libsuitesparse-dev libopenblas0-pthread libfftw3-dev
  libgmsh-dev gmsh
  libtomlplusplus-dev libcli11-dev nlohmann-json3-dev libboost-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenmpi-dev openmpi-bin
  python3 python3-numpy python3-meshio python3-matplotlib
  python3-dev pybind11-dev python3-pybind11
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

jobs="$(nproc 2>/dev/null || echo 2)"
build="${SHROUDSIM_BUILD_DIR:-build}"
# shellcheck disable=SC2086  # SHROUDSIM_CMAKE_ARGS is a list of options
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release ${SHROUDSIM_CMAKE_ARGS:-} >/dev/null
if ! cmake --build "$build" -j "$jobs" >"$build/build.log" 2>&1; then
  grep -E -A5 "error" "$build/build.log" | head -60 >&2
  echo "setup: the build failed (full log: $build/build.log)" >&2
  exit 1
fi

case "$mode" in
  demo) exec "$build/src/app/shroudsim" run cases/shrouded_wheel.toml ;;
  test) exec ctest --test-dir "$build" --output-on-failure -j "$jobs" ;;
  build) echo "setup: built $build/src/app/shroudsim" >&2 ;;
esac
