#!/bin/sh
# regress removes from OUT the outputs an earlier regress left of scenarios
# no longer in DIR, says so, and leaves everything else in OUT alone.
#
#   sh regress_stale.sh DOVETAIL SCENARIOS OUT
set -u
program=$1 scenarios=$2 out=$3
fail() {
  echo "regress_stale: $*"
  cat "$out/stderr.txt"
  exit 1
}
rm -rf "$out" && mkdir -p "$out/reports/gone" "$out/reports/kept" || exit 1
# A report an earlier regress of this folder wrote for a scenario deleted since.
printf '{\n  "format": "dovetail-scenario-report",\n  "version": 1,\n  "file": "%s/gone.lua",\n  "outcome": "passed"\n}\n' \
  "$scenarios" > "$out/reports/gone.json" || exit 1
echo 'an old log' > "$out/reports/gone.log"
echo 'not a png' > "$out/reports/gone/final.png"
# Files of the user's beside them: a JSON file that is no report, with a log,
# and a folder of its own.
echo '{"a": 1}' > "$out/reports/notes.json"
echo 'notes' > "$out/reports/notes.log"
echo 'mine' > "$out/reports/kept/final.png"
echo 'mine' > "$out/reports/kept/other.txt"
printf '{\n  "format": "dovetail-scenario-report"\n}\n' > "$out/reports/kept.json"
# Reports beside a log that regress must not take for its own: one of a
# scenario elsewhere that still exists (a `run --report` into OUT), and one
# another folder's regress left of a scenario gone from there.
printf '{\n  "format": "dovetail-scenario-report",\n  "file": "%s/01_peg_in_hole.lua"\n}\n' \
  "$scenarios" > "$out/reports/mine.json"
echo 'my log' > "$out/reports/mine.log"
printf '{\n  "format": "dovetail-scenario-report",\n  "file": "%s/elsewhere/gone.lua"\n}\n' \
  "$out" > "$out/reports/theirs.json"
echo 'their log' > "$out/reports/theirs.log"
# JSON of odd types beside a log: no report, left alone (a "format" that is
# a number once ended regress with the JSON library's type error).
echo '{"format": 3, "file": 7}' > "$out/reports/odd.json"
echo 'odd log' > "$out/reports/odd.log"
# The first of the shipped scenarios only.
"$program" regress "$scenarios" --out "$out/reports" --shard 1/99 > /dev/null 2> "$out/stderr.txt" ||
  fail "regress failed"
grep -q "note: regress: removed from .*reports the outputs of 1 scenario no longer in .*: gone$" \
  "$out/stderr.txt" || fail "no note naming 'gone'"
for gone in gone.json gone.log gone; do
  [ ! -e "$out/reports/$gone" ] || fail "$gone is left"
done
for kept in notes.json notes.log kept/final.png kept/other.txt kept.json mine.json mine.log \
  theirs.json theirs.log odd.json odd.log 01_peg_in_hole.json; do
  [ -e "$out/reports/$kept" ] || fail "$kept was removed"
done
