#!/usr/bin/env bash
# One command for the benchmark table: builds papertear_bench (Release, -march=native) in its
# own build directory, runs the suite with repetitions and writes the medians and ratios to
# bench/results/latest.json (Google Benchmark's JSON), latest-summary.json and latest.md.
#
#   bench/run.sh                 # 30x30x5, 90x90x5, 300x300x5, tearing, render and probes
#   HUGE=1 bench/run.sh          # also 1000x1000x5 (minutes of setup, ~1.3 GB)
#   REPS=3 MIN_TIME=0.1 bench/run.sh
#   FILTER='90x90x5' bench/run.sh  # any Google Benchmark regular expression
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build/bench-release}
reps=${REPS:-5}
min_time=${MIN_TIME:-0.2}
sizes='30x30x5|90x90x5|300x300x5|30x20x3'
if [[ "${HUGE:-0}" == 1 ]]; then sizes="$sizes|1000x1000x5"; fi
filter=${FILTER:-"^(step|force|fracture)/[a-z]+/($sizes)/|^render/|^probe/"}
out=$root/bench/results
mkdir -p "$out"

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DPAPERTEAR_BUILD_TESTS=OFF -DPAPERTEAR_BUILD_TOOLS=ON -DPAPERTEAR_BUILD_BENCH=ON >/dev/null  # tools: the renderer
cmake --build "$build" --target papertear_bench -j 2

"$build/bench/papertear_bench" --benchmark_filter="$filter" \
  --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
  --benchmark_min_time="$min_time" \
  --benchmark_out="$out/latest.json" --benchmark_out_format=json

python3 "$root/bench/summarize.py" "$out/latest.json" "$out/latest.md" "$out/latest-summary.json"
echo "wrote $out/latest.md"
