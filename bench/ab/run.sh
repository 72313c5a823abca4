#!/usr/bin/env bash
# The step of a base revision against the working tree's, side by side in one process
# (bench/ab/step_ab.cpp): builds each tree's library in Release, links it with the shim
# bench/ab/step_library.cpp into a shared object, and times the quiet 90 x 90 x 5 sheet and the
# torn default scene, alternating the two builds in blocks of steps. With RENDER=1 the same for
# the torn 1280 x 720 frame of render/frame/torn (the renderer's library and the shim
# bench/ab/render_library.cpp), one frame per block.
#
#   bench/ab/run.sh                  # base: HEAD (the working tree's uncommitted changes vs HEAD)
#   bench/ab/run.sh 4e23c07          # any revision that has bench::default_scene_at
#   THREADS=1 NX=300 BLOCKS=8 STEPS=4 bench/ab/run.sh HEAD~1
#   RENDER=1 BLOCKS=30 bench/ab/run.sh   # a base that has bench::torn_render_sheet
#
# Prints per case the two medians and the median of the blocks' ratios B / A (B: the working
# tree) with its quartiles. The base's tree is a git worktree under build/ab/, kept for reruns.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
rev=$(git -C "$root" rev-parse --short "${1:-HEAD}")
out=$root/build/ab
tree=$out/tree-$rev
mkdir -p "$out"
if [[ ! -d "$tree" ]]; then
  git -C "$root" worktree prune  # a tree deleted with build/ is still registered until pruned
  git -C "$root" worktree add --detach "$tree" "$rev" >/dev/null 2>&1
fi

kind=step
if [[ "${RENDER:-0}" == 1 ]]; then kind=render; fi

# build_library SOURCE_TREE BUILD_DIR OUTPUT.so: the step's library, or the renderer's.
build_library() {
  local tools=OFF target=papertear shim=step_library.cpp libs=("$2/libpapertear.a") extra=()
  if [[ $kind == render ]]; then
    tools=ON target=papertear_render shim=render_library.cpp
    libs=("$2/tools/render/libpapertear_render.a" "$2/tools/libpapertear_io.a" "$2/libpapertear.a")
    extra=(-I/usr/include/eigen3 -lembree3 -lpng -ltinygltf -ltomlplusplus)
  fi
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPAPERTEAR_BUILD_TESTS=OFF \
    -DPAPERTEAR_BUILD_TOOLS=$tools -DPAPERTEAR_BUILD_BENCH=OFF >/dev/null
  cmake --build "$2" --target $target >/dev/null
  g++ -O2 -fPIC -shared -std=c++20 -march=native -ffp-contract=off -I"$1" -I"$2" "$root/bench/ab/$shim" \
    "$1/bench/bench_cases.cpp" "${libs[@]}" "${extra[@]}" -ltbb -lbenchmark -Wl,-Bsymbolic -o "$3"
}
build_library "$tree" "$out/build-$rev" "$out/base-$kind.so"
build_library "$root" "$out/build-head" "$out/head-$kind.so"
g++ -O2 -std=c++20 "$root/bench/ab/step_ab.cpp" -ldl -o "$out/step_ab"

echo "A: $rev, B: the working tree"
if [[ $kind == render ]]; then
  "$out/step_ab" "$out/base-render.so" "$out/head-render.so" render "${THREADS:-2}" "${BLOCKS:-20}"
  exit 0
fi
for torn in 0 1; do
  "$out/step_ab" "$out/base-step.so" "$out/head-step.so" "${NX:-90}" "${THREADS:-2}" "$torn" "${BLOCKS:-12}" "${STEPS:-40}"
done
