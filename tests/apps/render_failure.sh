#!/bin/sh
# A final frame that cannot be drawn (the hand 1e40 m away) is the run's
# error, named with the frame; the report is written all the same.
#
#   sh render_failure.sh DOVETAIL SCENARIO TRACE OUT
set -u
program=$1 scenario=$2 trace=$3 out=$4
rm -rf "$out" && mkdir -p "$out" || exit 1
# The last sample's wrist x far away: the hand ends there.
last=$(wc -l < "$trace")
awk -F, -v OFS=, -v last="$last" 'NR == last { $2 = "1e40" } 1' "$trace" > "$out/far.csv" || exit 1
"$program" replay "$scenario" "$out/far.csv" --render "$out/frames" --report "$out/report.json" \
  --quiet > "$out/stdout.txt" 2> "$out/stderr.txt"
code=$?
[ -f "$out/report.json" ] || { echo "no report (exit $code)"; cat "$out/stderr.txt"; exit 1; }
if [ $code -ne 0 ]; then
  [ $code -eq 1 ] || { echo "exit $code, expected 1"; exit 1; }
  grep -q 'final.png: the frame at t=.* s cannot be drawn' "$out/stderr.txt" ||
    { echo "the error does not name the frame:"; cat "$out/stderr.txt"; exit 1; }
  grep -q '"state_hash"' "$out/report.json" || { echo "the report lost the simulation"; exit 1; }
fi
echo "report written (exit $code)"
