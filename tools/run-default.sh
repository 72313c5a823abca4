#!/usr/bin/env bash
# Installs the dependencies, builds the `papertear` tool (release preset) and runs the
# default scene: the paper's 90 × 90 × 5 sheet pulled apart. Frames and summary.json go to
# out/default.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash tools/install-deps.sh

cmake --preset release
cmake --build --preset release --target papertear_cli

cli=build/release/tools/papertear
if [[ ! -x "$cli" ]]; then
  echo "run-default: $cli was not built" >&2
  exit 1
fi

out=out/default
"$cli" run --out "$out"

echo
echo "run-default: outputs are in $(pwd)/$out"
ls -l "$out"
