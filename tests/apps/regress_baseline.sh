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
# A scenario whose report names a path beside its folder: an open mesh's warning.
mkdir -p "$out/a/meshes" && cp "$(dirname "$0")/../data/open_box.obj" "$out/a/meshes/" || exit 1
cat > "$out/a/s/05_open.lua" <<'LUA'
return scenario { name = "open", units = "mm", duration = 0.1,
  parts = { box = part { mesh = "../meshes/open_box.obj" } } }
LUA
# The baseline, made from inside the folder ("."), and the same scenarios
# in another folder, named by its full path: nothing changed.
(cd "$out/a/s" && "$program" regress . --out ../../base > /dev/null 2>&1) ||
  fail "making the baseline failed"
cp -RP "$out/a" "$out/b" || exit 1
regress 0 "$out/b/s" --baseline "$out/base" --out "$out/o" --junit "$out/j.xml"
grep -q "open_box.obj" "$out/o/05_open.json" || fail "the report names no mesh path: the test tests nothing"
rm "$out/a/s/05_open.lua" "$out/b/s/05_open.lua" "$out/base/05_open."* && rm -r "$out/base/05_open" "$out/o/05_open"* ||
  exit 1
grep -q "^3 of 3 scenarios passed, 3 the same as the baseline (" "$out/stdout.txt" || fail "not every scenario passed the same"
grep -q "CHANGED" "$out/stdout.txt" && fail "a scenario moved to another folder changed"
# A comment added above every clause moves them all a line down: no change.
{ echo '-- reviewed'; cat "$out/b/s/01_peg_in_hole.lua"; } > "$out/commented.lua" &&
  mv "$out/commented.lua" "$out/b/s/01_peg_in_hole.lua" || exit 1
regress 0 "$out/b/s" --baseline "$out/base" --out "$out/o"

# The baseline is an input: no summary may be written into it, and one that
# holds no report of the folder's scenarios (an empty folder, the scenarios'
# own folder) is an error, not a pass that compared nothing.
regress 2 "$out/b/s" --baseline "$out/base" --out "$out/o" --html "$out/base/01_peg_in_hole.json"
grep -q "is in the baseline folder" "$out/stderr.txt" || fail "--html into the baseline not refused"
mkdir -p "$out/empty" || exit 1
regress 1 "$out/b/s" --baseline "$out/empty" --out "$out/o"
grep -q "empty: holds no report of a scenario in" "$out/stderr.txt" || fail "an empty baseline passed"
regress 1 "$out/b/s" --baseline "$out/b/s" --out "$out/o"
grep -q "s: holds no report of a scenario in" "$out/stderr.txt" ||
  fail "the scenarios' folder taken for the baseline was not refused"
# A report of a scenario no longer in the folder is named.
cp "$out/base/04_stacked_bricks.json" "$out/base/05_gone.json" || exit 1
regress 0 "$out/b/s" --baseline "$out/base" --out "$out/o"
grep -q "note: regress: the baseline .*base has reports of 1 scenario not in .*: 05_gone$" \
  "$out/stderr.txt" || fail "no note naming the baseline's report of a scenario gone"
rm "$out/base/05_gone.json"

# A step done at another time: CHANGED, with that difference, exit 3.
sed 's/"done_at": 2.41[0-9]*/"done_at": 2.5/' "$out/base/01_peg_in_hole.json" > "$out/edited.json" &&
  mv "$out/edited.json" "$out/base/01_peg_in_hole.json" || exit 1
grep -q '"done_at": 2.5' "$out/base/01_peg_in_hole.json" || fail "the baseline was not edited"
regress 3 "$out/b/s" --baseline "$out/base" --out "$out/o" --junit "$out/j.xml" --html "$out/r.html"
grep -q '^CHANGED 01_peg_in_hole .*changed from the baseline: steps\[insert\]\.done_at: 2\.41[0-9]*, was 2\.5$' \
  "$out/stdout.txt" || fail "no CHANGED line naming the step's time"
grep -q "^PASS  *04_stacked_bricks" "$out/stdout.txt" || fail "the other scenario did not pass"
grep -q "^1 of 2 scenarios passed, 1 changed from the baseline, 1 the same as the baseline (" "$out/stdout.txt" ||
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
grep -q "^PASS  *04_stacked_bricks .*(no baseline)$" "$out/stdout.txt" || fail "no '(no baseline)' note"
grep -q "^2 of 2 scenarios passed, 1 without a baseline, 1 the same as the baseline (" "$out/stdout.txt" ||
  fail "no summary counting the scenario without a baseline"
regress 0 "$out/b/s" --baseline "$out/base" --out "$out/o" --baseline-tolerance 0.1 --junit "$out/j.xml"
grep -q "<system-out>no baseline to compare with: .*04_stacked_bricks.json</system-out>" "$out/j.xml" ||
  fail "the JUnit XML does not say a scenario had no baseline"
echo '{' > "$out/base/04_stacked_bricks.json"
regress 3 "$out/b/s" --baseline "$out/base" --out "$out/o"
grep -q "^ERROR  *04_stacked_bricks .*base/04_stacked_bricks.json: not a Dovetail scenario report (at line" \
  "$out/stdout.txt" || fail "no error naming the baseline that is no report"
echo "regress_baseline: ok"
