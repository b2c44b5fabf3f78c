#!/usr/bin/env bash
# The sanitizer leg of the CI (.ci/run): a Debug build with AddressSanitizer and
# UndefinedBehaviorSanitizer (SHROUDSIM_SANITIZE=ON, no benchmarks, portable code) in
# build-asan/, then the quick unit tests (ctest label "fast") with leak detection on. Any
# sanitizer report fails its test (UBSan does not recover; ASan and LSan exit non-zero).
#   tools/ci_sanitize.sh            configure, build, test
# SHROUDSIM_ASAN_BUILD_DIR overrides the build folder. Needs the packages tools/setup.sh installs.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${SHROUDSIM_ASAN_BUILD_DIR:-build-asan}"
jobs="$(nproc 2>/dev/null || echo 2)"

start=$SECONDS
# Debug (assertions, Eigen's index checks) at -O1, as the sanitizers' documentation advises:
# at -O0 the Eigen-heavy tests run several times slower still.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" -DSHROUDSIM_SANITIZE=ON \
  -DSHROUDSIM_BUILD_BENCHMARKS=OFF -DSHROUDSIM_NATIVE=OFF -DSHROUDSIM_WERROR=ON >/dev/null
# The test executables run at build time too (gtest_discover_tests lists their tests), under
# the same sanitizer options as the tests.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/tools/lsan.supp:print_suppressions=0"
if ! nice -n 10 cmake --build "$build" -j "$jobs" >"$build/build.log" 2>&1; then
  grep -E -A5 "error" "$build/build.log" | head -60 >&2
  echo "ci_sanitize: the build failed (full log: $build/build.log)" >&2
  exit 1
fi
built=$SECONDS
echo "ci_sanitize: built $build in $((built - start)) s" >&2
status=0
ctest --test-dir "$build" -L fast --output-on-failure -j "$jobs" || status=$?
echo "ci_sanitize: tests took $((SECONDS - built)) s" >&2
exit $status
