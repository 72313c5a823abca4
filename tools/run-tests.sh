#!/usr/bin/env bash
# Installs the dependencies, builds every target of the release preset and runs the whole
# test suite (unit tests, determinism, the CLI and the installed-package test, then the
# client tests).
# Exits non-zero if the build or any test fails.
# PAPERTEAR_WERROR=ON in the environment makes compiler warnings errors.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash tools/install-deps.sh

cmake --preset release -DPAPERTEAR_WERROR="${PAPERTEAR_WERROR:-OFF}"
cmake --build --preset release
# The unit, determinism and CLI tests; then, as their own stage, the client tests: what a
# run writes, read by the glTF validator, ffprobe, Blender and Chromium (tests/clients/).
ctest --preset release --output-on-failure -j2 -LE clients
bash tools/clients/install.sh build/release/clients
ctest --preset release --output-on-failure -j2 -L clients
