#!/usr/bin/env bash
# Installs the dependencies, builds every target of the release preset and runs the whole
# test suite (unit tests, determinism, the CLI and the installed-package test).
# Exits non-zero if the build or any test fails.
# PAPERTEAR_WERROR=ON in the environment makes compiler warnings errors.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash tools/install-deps.sh

cmake --preset release -DPAPERTEAR_WERROR="${PAPERTEAR_WERROR:-OFF}"
cmake --build --preset release
ctest --preset release --output-on-failure -j2
