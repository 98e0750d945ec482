#!/bin/sh
# Builds the libFuzzer targets (clang, AddressSanitizer, UndefinedBehaviorSanitizer)
# in build-fuzz/ and runs them one after the other.
#   scripts/fuzz.sh                 every target for 30 s
#   scripts/fuzz.sh 600             every target for 600 s (a long run)
#   scripts/fuzz.sh 60 tri_tri ...  only the named targets (names as in fuzz/corpus/)
# Seeds come from fuzz/corpus/<target>/ and stay untouched; what the fuzzer
# adds goes to build-fuzz/corpus/<target>/, crashes, hangs and out-of-memory
# inputs to build-fuzz/crashes/<target>/. Prints per target the executions,
# the time and the crash files found; exits 1 when a target found any.
# Environment: BUILD_DIR (default build-fuzz), JOBS (default: number of cores),
# FUZZ_SEED (libFuzzer's -seed; unset, each run explores differently).
# docs/reliability.md explains the targets and records their results.
set -eu

root=$(cd "$(dirname "$0")/.." && pwd)
build="${BUILD_DIR:-$root/build-fuzz}"
jobs="${JOBS:-$(nproc 2>/dev/null || echo 2)}"
seconds="${1:-30}"
[ $# -gt 0 ] && shift

all_targets="glove_trace glove_plan pose_list box_file tri_tri mesh_obj mesh_stl mesh_ply mesh_gltf mesh_glb scenario"
targets="${*:-$all_targets}"

# Longest input per target, in bytes: room for the seeds, small enough to stay fast.
max_len() {
  case "$1" in
    tri_tri) echo 73 ;;                          # mode byte + 18 coordinates
    glove_plan | pose_list | box_file) echo 4096 ;;
    scenario) echo 8192 ;;
    glove_trace | mesh_obj | mesh_stl | mesh_ply) echo 16384 ;;
    *) echo 65536 ;;                             # glTF: JSON with embedded buffers, GLB
  esac
}

if ! command -v clang++ >/dev/null 2>&1; then
  echo "fuzz: clang++ not found; scripts/install-deps.sh installs it (clang, libfuzzer-14-dev)" >&2
  exit 1
fi

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DDOVETAIL_BUILD_FUZZ=ON -DDOVETAIL_BUILD_TESTS=OFF -DDOVETAIL_BUILD_BENCH=OFF >/dev/null
build_targets=""
for t in $targets; do build_targets="$build_targets fuzz_$t"; done
# shellcheck disable=SC2086
cmake --build "$build" -j "$jobs" --target $build_targets

export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

summary=""
found_total=0
for t in $targets; do
  corpus="$build/corpus/$t"
  crashes="$build/crashes/$t"
  mkdir -p "$corpus" "$crashes"
  dict=""
  seed=""
  [ -n "${FUZZ_SEED:-}" ] && seed="-seed=$FUZZ_SEED"
  [ -f "$root/fuzz/$t.dict" ] && dict="-dict=$root/fuzz/$t.dict"
  case "$t" in mesh_*) [ -f "$root/fuzz/mesh.dict" ] && dict="-dict=$root/fuzz/mesh.dict" ;; esac
  # Assimp (the system library behind the mesh targets) leaks on some
  # malformed files it refuses (docs/reliability.md); leak checks there would
  # stop every run at the first such file, so only the other targets check.
  leaks=1
  case "$t" in mesh_*) leaks=0 ;; esac
  log="$build/fuzz-$t.log"
  echo "fuzz: $t for ${seconds}s (log: $log)" >&2
  before=$(find "$crashes" -type f | wc -l)
  start=$(date +%s)
  # shellcheck disable=SC2086
  ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=$leaks" "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -max_len="$(max_len "$t")" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$crashes/" $dict $seed \
    "$corpus" "$root/fuzz/corpus/$t" >"$log" 2>&1 || true
  elapsed=$(($(date +%s) - start))
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  after=$(find "$crashes" -type f | wc -l)
  found=$((after - before))
  found_total=$((found_total + found))
  line=$(printf '%-12s %8ss %12s execs %4s new crash files' "$t" "$elapsed" "${runs:-?}" "$found")
  echo "$line" >&2
  summary="$summary$line
"
done

echo
echo "target          time       executions   crashes (files in build-fuzz/crashes/<target>/)"
printf '%s' "$summary"
if [ "$found_total" -gt 0 ]; then
  echo "fuzz: $found_total crash, hang or out-of-memory input(s); reproduce with build-fuzz/fuzz/fuzz_<target> <file>" >&2
  exit 1
fi
