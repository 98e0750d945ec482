#!/bin/sh
# Where the open hand may lie on a bar and still grasp it: bars of 30, 40
# and 50 mm lying along x, the wrist 50 to 80 mm behind the bar's axis and
# the palm from 2 mm into the bar to 2.5 mm above it (its face is 10.45 mm
# below the wrist for the default hand), closing to POSTURE for 0.5 s.
# Prints one digit a placement (1: grasped as power) and the count.
#
#   sh docs/results/grasp_sweep.sh DOVETAIL [POSTURE]   (POSTURE: fist, power, ...)
set -u
dovetail=$(realpath "$1")
posture=${2:-fist}
work=$(mktemp -d) && cd "$work" || exit 1
total=0 passed=0
for diameter in 30 40 50; do
  line="d=$diameter:"
  for behind in 50 55 60 65 70 75 80; do
    for above in -2 -1.5 -1 -0.5 -0.25 0 0.1 0.3 0.5 1 1.5 2.5; do
      y=$(awk "BEGIN { print ($diameter / 2 + 10.45 + $above) / 1000 }")
      z=$(awk "BEGIN { print $behind / 1000 }")
      printf 'start 0 %s %s  1 0 0 0 open\nclose 0.5 %s\nwait 0.2\n' "$y" "$z" "$posture" > bar.plan
      cat > bar.lua <<LUA
return scenario { name = "bar", units = "mm",
  parts = { bar = part { shape = cylinder { diameter = $diameter, length = 120 },
                         at = { -60, 0, 0 }, turn = { y = 90 } } },
  hand = glove { plan = "bar.plan" }, expect = { grasped_as("bar", "power") } }
LUA
      r=$("$dovetail" run bar.lua 2>/dev/null | head -1 | grep -c passed)
      total=$((total + 1)) passed=$((passed + r)) line="$line$r"
    done
    line="$line "
  done
  echo "$line"
done
echo "grasped $passed of $total"
rm -rf "$work"
