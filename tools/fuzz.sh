#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer on) and fuzzes the scene parser,
# the sweep-file parser and the checkpoint loader for SECONDS each (default 60), starting from
# the seed corpora in tests/fuzz/corpus/. A crash, a leak, an input that takes over 10 s or
# 2 GB fails the script and leaves the input in build/fuzz/crash-*, timeout-* or oom-*: add it
# to the corpus and turn it into a regression test. CI runs it (`.ci/run`).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
seconds="${1:-60}"
targets=(scene sweep checkpoint)

bash tools/install-deps.sh
# -O1 -g1: with AddressSanitizer at -O2 -g, GCC spends 15 minutes on kernels/coarse_forces.cpp
# (the sanitizer presets use -O2 -g1 for that reason), and line tables are all a crash report
# needs.
CXX=clang++ cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DPAPERTEAR_FUZZ=ON \
  -DPAPERTEAR_BUILD_BENCH=OFF -DPAPERTEAR_BUILD_PYTHON=OFF >/dev/null
cmake --build build/fuzz -j2 --target $(printf 'papertear_%s_fuzz ' "${targets[@]}")

root="$PWD"
for target in "${targets[@]}"; do
  work="build/fuzz/corpus-$target"
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/$target/* "$work/"
  log="build/fuzz/$target.log"
  echo "fuzz: $target for ${seconds}s"
  # From the repository root, so that sweep seeds can name the scene corpus by relative path.
  if ! "build/fuzz/tests/fuzz/papertear_${target}_fuzz" "$work" -max_total_time="$seconds" \
       -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$root/build/fuzz/" -print_final_stats=1 \
       >"$log" 2>&1; then
    tail -40 "$log"
    echo "fuzz: $target FAILED (input saved in build/fuzz/, log $log)"
    exit 1
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$log" | tr '\n' ' '
  echo
done
echo "fuzz: ${targets[*]}: no crash, hang or leak in ${seconds}s each"
