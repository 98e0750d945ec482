#!/bin/sh
# regress --baseline: reports compared with an earlier regress's, a change
# named by its first difference, paths to the scenarios not counted.
#
#   sh regress_baseline.sh DOVETAIL SCENARIOS OUT
set -u
program=$1 scenarios=$2 out=$3
fail() {
  echo "regress_baseline: $*"
  cat "$out/stdout.txt" "$out/stderr.txt"
  exit 1
}
# regress EXPECTED_EXIT ARGS...: runs it, output in stdout.txt and stderr.txt.
regress() {
  expected=$1
  shift
  "$program" regress "$@" > "$out/stdout.txt" 2> "$out/stderr.txt"
  code=$?
  [ "$code" -eq "$expected" ] || fail "regress $* exited with $code, not $expected"
}
rm -rf "$out" && mkdir -p "$out/a/s" || exit 1
cp "$scenarios/01_peg_in_hole.lua" "$scenarios/04_stacked_bricks.lua" "$out/a/s/" || exit 1
ln -s "$(cd "$scenarios/../assets" && pwd)" "$out/a/assets" || exit 1
# The baseline, and the same scenarios in another folder: nothing changed.
regress 0 "$out/a/s" --out "$out/base"
cp -RP "$out/a" "$out/b" || exit 1
regress 0 "$out/b/s" --baseline "$out/base" --out "$out/o" --junit "$out/j.xml"
grep -q "^2 of 2 scenarios passed (" "$out/stdout.txt" || fail "not every scenario passed"
grep -q "CHANGED" "$out/stdout.txt" && fail "a scenario moved to another folder changed"

# A step done at another time: CHANGED, with that difference, exit 3.
sed 's/"done_at": 2.41[0-9]*/"done_at": 2.5/' "$out/base/01_peg_in_hole.json" > "$out/edited.json" &&
  mv "$out/edited.json" "$out/base/01_peg_in_hole.json" || exit 1
grep -q '"done_at": 2.5' "$out/base/01_peg_in_hole.json" || fail "the baseline was not edited"
regress 3 "$out/b/s" --baseline "$out/base" --out "$out/o" --junit "$out/j.xml" --html "$out/r.html"
grep -q '^CHANGED 01_peg_in_hole .*changed from the baseline: steps\[insert\]\.done_at: 2\.41[0-9]*, was 2\.5$' \
  "$out/stdout.txt" || fail "no CHANGED line naming the step's time"
grep -q "^PASS   04_stacked_bricks" "$out/stdout.txt" || fail "the other scenario did not pass"
grep -q "^1 of 2 scenarios passed, 1 changed from the baseline (" "$out/stdout.txt" ||
  fail "no summary counting the change"
grep -q '<failure message="changed from the baseline: steps\[insert\]' "$out/j.xml" ||
  fail "the JUnit XML has no failure for the change"
grep -q "changed from the baseline (1 differences)" "$out/r.html" || fail "the HTML shows no change"
# Within a tolerance the step's time is alike.
regress 0 "$out/b/s" --baseline "$out/base" --out "$out/o" --baseline-tolerance 0.1

# A scenario without a baseline passes with a note; a baseline that is no
# report is an error naming it.
rm "$out/base/04_stacked_bricks.json"
regress 0 "$out/b/s" --baseline "$out/base" --out "$out/o" --baseline-tolerance 0.1
grep -q "^PASS   04_stacked_bricks .*(no baseline)$" "$out/stdout.txt" || fail "no '(no baseline)' note"
grep -q "^2 of 2 scenarios passed, 1 without a baseline (" "$out/stdout.txt" ||
  fail "no summary counting the scenario without a baseline"
echo '{' > "$out/base/04_stacked_bricks.json"
regress 3 "$out/b/s" --baseline "$out/base" --out "$out/o"
grep -q "^ERROR  04_stacked_bricks .*base/04_stacked_bricks.json: not a Dovetail scenario report$" \
  "$out/stdout.txt" || fail "no error naming the baseline that is no report"
echo "regress_baseline: ok"
