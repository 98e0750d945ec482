#!/bin/sh
# Speed against accuracy, charted: runs the benchmarks behind docs/benchmarks.md
# ("Speed against accuracy") and writes their tables to docs/results/ and their
# charts (PNG and SVG, gnuplot) to docs/images/.
#   scripts/charts.sh [DATA]    DATA: the folder with stanford-bunny.obj, teapot.obj
#                               and fandisk.obj (default ../shared/data)
# Environment: BUILD_DIR (default build), DIRECTIONS (100), RUNS (5), STEPS (180).
# Takes about 20 minutes on 2 cores, most of it the sliding sweep and Bullet's
# GImpact (the slowest peer) in the tumbling runs.
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
data=${1:-../shared/data}
build=${BUILD_DIR:-build}
directions=${DIRECTIONS:-100}
runs=${RUNS:-5}
steps=${STEPS:-180}
if ! command -v gnuplot >/dev/null 2>&1; then
  echo "charts: gnuplot not found; scripts/install-deps.sh installs it (gnuplot-nox)" >&2
  exit 1
fi
for f in stanford-bunny.obj teapot.obj fandisk.obj; do
  [ -f "$data/$f" ] || { echo "charts: $data/$f not found (give the data folder)" >&2; exit 1; }
done
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc)" --target accuracy_bench tumble_bench hand_bench >/dev/null
mkdir -p docs/results docs/images

chart() {  # name title a b
  name=$1 title=$2 a=$3 b=$4
  echo "charts: $name: accuracy ($directions directions x 7 gaps, $runs runs)" >&2
  "$build/bench/accuracy_bench" "$a" "$b" --directions "$directions" --runs "$runs" \
    --table "docs/results/accuracy_$name.dat" >"docs/results/accuracy_$name.txt"
  echo "charts: $name: tumbling ($steps turns per distance)" >&2
  "$build/bench/tumble_bench" "$a" "$b" --steps "$steps" --distances 0:3:0.1 \
    --table "docs/results/tumble_$name.dat" >"docs/results/tumble_$name.txt"
  for format in png svg; do
    if [ "$format" = png ]; then term="pngcairo size 900,560 font 'sans,10'"; else term="svg size 900,560 font 'sans,10'"; fi
    gnuplot <<GNUPLOT
set terminal $term
set output "docs/images/accuracy_$name.$format"
set title "$title: query time against error, contact-distance poses"
set xlabel "false positives + false negatives (% of poses)"
set ylabel "mean query time (µs, log)"
set logscale y
set grid
set key outside right top
file = "docs/results/accuracy_$name.dat"
points = "exact volume hull peer hull-peer"
curves = "depth-obb depth-dop18 depth-aabb plane"
plot for [i=1:words(points)] file using (strcol(1) eq word(points, i) ? \$5 + \$6 : NaN):3 \
       with points pt i ps 1.5 title word(points, i), \
     for [i=1:words(curves)] file using (strcol(1) eq word(curves, i) ? \$5 + \$6 : NaN):3 \
       with linespoints pt i + 3 lw 1.5 title word(curves, i)
set output "docs/images/tumble_$name.$format"
set title "$title: Zachmann's protocol, query time against the distance of the centres"
set xlabel "distance between the centres (objects scaled into [-1, 1]^3)"
set ylabel "mean query time over the turns (µs, log)"
methods = "boxtree dop6 dop14 dop18 dop26 aabb obb hull-plane fcl-obbrss bullet-gimpact libccd-gjk"
file = "docs/results/tumble_$name.dat"
plot for [i=1:words(methods)] file using (strcol(1) eq word(methods, i) ? \$2 : NaN):5 \
  with linespoints pt i lw 1.5 title word(methods, i)
GNUPLOT
  done
}

# Sliding: accuracy against cost, the peg slid down its hole's wall.
echo "charts: sliding ($runs runs per setting)" >&2
"$build/bench/hand_bench" --runs "$runs" --sweep docs/results/sliding_sweep.dat >docs/results/sliding_sweep.txt
for format in png svg; do
  if [ "$format" = png ]; then term="pngcairo size 900,560 font 'sans,10'"; else term="svg size 900,560 font 'sans,10'"; fi
  gnuplot <<GNUPLOT
set terminal $term
set termoption noenhanced
set output "docs/images/sliding_sweep.$format"
set title "Sliding a 10,240-triangle peg down its hole's wall: gap left at contact against cost"
set xlabel "interaction step, 95th percentile over the frames in contact (ms)"
set ylabel "gap between peg and block in contact, median (µm, log)"
set logscale y
set grid
set key off
set offsets graph 0.05, graph 0.25, 0, 0
file = "docs/results/sliding_sweep.dat"
plot file using 3:6 with points pt 7 ps 1.5, file using 3:6:(strcol(1)) with labels offset 1,0.6 left font ",9"
GNUPLOT
done

chart bunny "Stanford bunny against itself" "$data/stanford-bunny.obj" "$data/stanford-bunny.obj"
chart teapot_fandisk "Teapot against fandisk" "$data/teapot.obj" "$data/fandisk.obj"
# Two parts of the 2-cylinder engine (Debian's assimp-testmodels), each in its own frame.
engine=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
if [ -f "$engine" ]; then
  chart engine_parts "Engine parts nodes[71] against nodes[72]" "$engine#nodes[71]" "$engine#nodes[72]"
else
  echo "charts: $engine not found (assimp-testmodels): the engine pair is left out" >&2
fi
echo "charts: written docs/images/{accuracy,tumble}_*.{png,svg} and docs/results/{accuracy,tumble}_*" >&2
