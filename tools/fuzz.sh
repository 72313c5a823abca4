#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer on) and fuzzes the scene parser and
# the checkpoint loader for SECONDS each (default 60), starting from the seed corpora in
# tests/fuzz/corpus/. A crash leaves its input in build/fuzz/crash-*: add it to the corpus
# and turn it into a regression test.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
seconds="${1:-60}"

bash tools/install-deps.sh
CXX=clang++ cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPAPERTEAR_FUZZ=ON \
  -DPAPERTEAR_BUILD_BENCH=OFF >/dev/null
cmake --build build/fuzz -j2 --target papertear_scene_fuzz papertear_checkpoint_fuzz

for target in scene checkpoint; do
  work="build/fuzz/corpus-$target"
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/$target/* "$work/"
  echo "fuzz: $target for ${seconds}s"
  (cd build/fuzz && "./tests/fuzz/papertear_${target}_fuzz" "corpus-$target" \
     -max_total_time="$seconds" -print_final_stats=1 2>&1 | tail -3)
done
