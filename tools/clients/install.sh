#!/usr/bin/env bash
# Installs the npm packages of the client tests and the viewer (package.json beside this
# file: glTF validator, three.js, playwright-core) into DEST/node_modules, exactly as the
# lock file pins them. Quick and offline when DEST already holds them.
#   bash tools/clients/install.sh [DEST]     (default: build/clients)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
dest="${1:-$here/../../build/clients}"
mkdir -p "$dest"
if [[ -d "$dest/node_modules" ]] && cmp -s "$here/package-lock.json" "$dest/package-lock.json"; then
  exit 0
fi
command -v npm >/dev/null || { echo "clients/install: npm is missing (bash tools/install-deps.sh)" >&2; exit 1; }
cp "$here/package.json" "$here/package-lock.json" "$dest/"
# No browser download: the tests drive Debian's chromium.
(cd "$dest" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error)
