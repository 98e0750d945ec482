#!/bin/sh
# An interrupted regress stops its runs, leaves none behind, writes a report
# for every scenario and its summaries, and exits 128 + the signal.
#
#   sh regress_interrupt.sh DOVETAIL OUT
set -u
program=$1 out=$2
rm -rf "$out" && mkdir -p "$out/scenarios" || exit 1
for name in a b c; do
  # 36 million frames: minutes, stopped long before.
  echo 'return scenario { name = "slow", duration = 3600, time_step = 0.0001,
    parts = { a = part { shape = box { size = { 10, 10, 10 } } } } }' > "$out/scenarios/$name.lua"
done
# What an earlier regress left of the scenario that will not run must not stand.
mkdir -p "$out/reports/c" && echo '{"outcome": "passed"}' > "$out/reports/c.json" &&
  echo 'an old log' > "$out/reports/c.log" && echo 'not a png' > "$out/reports/c/final.png" || exit 1
"$program" regress "$out/scenarios" --out "$out/reports" -j 2 --junit "$out/junit.xml" \
  --html "$out/report.html" > "$out/stdout.txt" 2>&1 &
regress=$!
# Both runs have started once their logs exist.
tries=0
while [ ! -f "$out/reports/a.log" ] || [ ! -f "$out/reports/b.log" ]; do
  tries=$((tries + 1))
  [ $tries -gt 600 ] && { echo "the runs did not start"; kill -KILL $regress; exit 1; }
  sleep 0.1
done
sleep 0.5
kill -TERM $regress
wait $regress
code=$?
fail() {
  echo "$1"
  cat "$out/stdout.txt"
  ls -l "$out/reports"
  ps -eo pid,ppid,stat,args | grep "[d]ovetail"
  exit 1
}
[ $code -eq 143 ] || fail "exit code $code, expected 143"
if pgrep -f "$out/scenarios" > /dev/null; then fail "a run outlived regress"; fi
grep -q "stopped: regress was interrupted by signal 15" "$out/stdout.txt" || fail "no stopped run"
grep -q "c .*not run: regress was interrupted" "$out/stdout.txt" || fail "no run left out"
grep -q 'tests="3" failures="0" errors="3"' "$out/junit.xml" || fail "no JUnit summary"
grep -q '0 of 3 scenarios passed, 3 errors; interrupted by signal 15\.' "$out/report.html" ||
  fail "the HTML summary does not say it was interrupted"
for name in a b c; do
  grep -q '"outcome": "error"' "$out/reports/$name.json" || fail "no report for $name"
done
! grep -q 'an old log' "$out/reports/c.log" || fail "the old log of c stands"
[ ! -f "$out/reports/c/final.png" ] || fail "the old final frame of c stands"
echo "interrupted as expected"
