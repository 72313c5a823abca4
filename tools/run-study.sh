#!/usr/bin/env bash
# The parameter study of docs/study.md: three one-factor sweeps (fibre length, block width,
# interlayer bond) x 4 seeds on a 60 x 60 x 5 copy-paper sheet. Runs them (a few minutes on
# 2 cores), copies the plots into docs/study/ and prints the tables of means and spreads.
#   bash tools/run-study.sh            # uses build/release/tools/papertear
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bin=${PAPERTEAR:-build/release/tools/papertear}
out=${OUT:-out/study}
for study in fiber_length block_width interlayer; do
  "$bin" sweep "docs/study/$study.toml" --out "$out/$study" --quiet
  for plot in "$out/$study"/plots/{separation_roughness,peeled_area,peak_grip_force}_vs_material.*.png; do
    [[ -e "$plot" && "$plot" != *strain_surface* ]] || continue  # set equal to strain_layer
    name=$(basename "$plot")
    cp "$plot" "docs/study/${name/material./}"
  done
done
python3 docs/study/table.py "$out"/{fiber_length,block_width,interlayer}/sweep.csv
