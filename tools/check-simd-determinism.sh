#!/usr/bin/env bash
# Builds the library for x86-64-v2 (SSE4.2), x86-64-v3 (AVX2), x86-64-v4 (AVX-512, when
# this CPU has it) and with SIMD off, runs the same short scenes with each, and fails unless
# every build prints the same digests. The kernels' vector bodies and scalar tails perform the
# same IEEE operations in the same order per element, so the vector width must not matter.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

variants=("x86-64-v2 ON" "x86-64-v3 ON" "x86-64-v2 OFF")
if grep -q avx512f /proc/cpuinfo; then variants+=("x86-64-v4 ON"); fi

reference=""
for v in "${variants[@]}"; do
  read -r arch simd <<<"$v"
  dir="build/simd-${arch}-${simd}"
  mkdir -p build
  if ! { cmake -S tests/simd -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release \
          -DPAPERTEAR_ARCH="$arch" -DPAPERTEAR_SIMD="$simd" && cmake --build "$dir" -j2; } >"$dir.log" 2>&1; then
    cat "$dir.log" >&2
    echo "check-simd-determinism: the $arch build with SIMD $simd failed" >&2
    exit 1
  fi
  out=$("$dir/simd_digests")
  printf '%s (SIMD %s):\n%s\n' "$arch" "$simd" "$out"
  if [[ -z "$reference" ]]; then
    reference="$out"
  elif [[ "$out" != "$reference" ]]; then
    echo "check-simd-determinism: $arch with SIMD $simd gives other digests than the first build" >&2
    exit 1
  fi
done
echo "check-simd-determinism: ${#variants[@]} builds agree"
