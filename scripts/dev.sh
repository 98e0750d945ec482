#!/bin/sh
# One entry point for users and CI:
#   scripts/dev.sh run     install what is missing, build Release, run the first shipped
#                          scenario (report and final frame in build/run/)
#   scripts/dev.sh test    install what is missing, build Release, run every test
#   scripts/dev.sh build   install what is missing, build Release
#   scripts/dev.sh bench   build, then run the polygon-level benchmark on built-in meshes
#   scripts/dev.sh tsan    build the collision, interaction and scripting tests with ThreadSanitizer
#                          (build-tsan/) and run the parallel ones
#   scripts/dev.sh asan    build everything with AddressSanitizer and UndefinedBehaviorSanitizer
#                          (build-asan/) and run every test
# Environment: BUILD_DIR (default build), JOBS (default: number of cores),
# DOVETAIL_WERROR=ON to treat warnings as errors (CI does).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
build_dir=${BUILD_DIR:-build}
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}
command=${1:-run}

sh scripts/install-deps.sh

if [ "$command" = tsan ]; then
  cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDOVETAIL_SANITIZE=thread \
    -DDOVETAIL_BUILD_BENCH=OFF -DDOVETAIL_WERROR="${DOVETAIL_WERROR:-OFF}" >/dev/null
  cmake --build build-tsan -j "$jobs" --target collision_tests interaction_tests scripting_tests
  TSAN_OPTIONS="halt_on_error=1 ${TSAN_OPTIONS:-}" build-tsan/tests/collision_tests \
    --gtest_filter='CollisionWorld.*:WorldDistance.*:Hierarchies.ParallelQueries*:TaskSystem.*'
  # The hand in a simulation at 2 and 8 collision threads.
  TSAN_OPTIONS="halt_on_error=1 ${TSAN_OPTIONS:-}" build-tsan/tests/interaction_tests \
    --gtest_filter='HandReplay.*:PegInHole.ARecorded*:GraspTypes.AGrasp*'
  # A shipped scenario at 1, 2 and 8 collision threads, and replayed.
  TSAN_OPTIONS="halt_on_error=1 ${TSAN_OPTIONS:-}" build-tsan/tests/scripting/scripting_tests \
    --gtest_filter='ShippedScenarios.*'
  exit 0
fi

if [ "$command" = asan ]; then
  # Any undefined behaviour stops the test (no recovery); a float division by
  # zero counts as undefined here too.
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DDOVETAIL_SANITIZE=address,undefined \
    -DCMAKE_CXX_FLAGS="-O1 -fno-sanitize-recover=all -fsanitize=float-divide-by-zero" \
    -DDOVETAIL_BUILD_BENCH=OFF -DDOVETAIL_WERROR="${DOVETAIL_WERROR:-OFF}" >/dev/null
  cmake --build build-asan -j "$jobs"
  # Leaks inside Mesa's software renderer are not Dovetail's (scripts/lsan.supp).
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=1 ${ASAN_OPTIONS:-}" \
    LSAN_OPTIONS="suppressions=$here/scripts/lsan.supp:print_suppressions=0 ${LSAN_OPTIONS:-}" \
    UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1 ${UBSAN_OPTIONS:-}" \
    ctest --test-dir build-asan --output-on-failure -j "$jobs"
  exit 0
fi

cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DDOVETAIL_WERROR="${DOVETAIL_WERROR:-OFF}" >/dev/null
cmake --build "$build_dir" -j "$jobs"

case "$command" in
  build) ;;
  run) "$build_dir/apps/dovetail" run --report "$build_dir/run/report.json" --render "$build_dir/run" ;;
  test) ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" ;;
  bench) "$build_dir/bench/polygon_bench" ;;
  *) echo "dev.sh: unknown command '$command' (run, test, build, bench, tsan, asan)" >&2; exit 2 ;;
esac
