#!/usr/bin/env bash
# Installs, builds and runs the demo on the built-in default scene; results land in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out/demo
# Train the default scene's neural asset (CUDA when a GPU is usable, else the CPU backend: ~1-2 min on 2 cores).
# An existing model is reused (delete out/demo/default.nbvh to retrain).
if [[ ! -f out/demo/default.nbvh ]]; then
  build/app/nbvh train default --out out/demo/default.nbvh --log out/demo/train_log.csv
fi
# Hybrid render (neural knot from the model) and the classical reference with the same material constants
# (4 spp: on the CPU device the scalar network takes ~1 min at 640x480).
# Both PNGs share one exposure (the classical render's automatic one), so that FLIP compares like with like.
build/app/nbvh render default --spp 4 --classical --out out/demo/classical.png --stats out/demo/classical_stats.json
EXPOSURE=$(sed -n 's/.*"stops": *\([-0-9.eE+]*\).*/\1/p' out/demo/classical_stats.json | head -1)
build/app/nbvh render default --spp 4 --model out/demo/default.nbvh --exposure "${EXPOSURE:-0}" --out out/demo/neural.png --stats out/demo/neural_stats.json
build/app/nbvh flip out/demo/classical.png out/demo/neural.png --heatmap out/demo/flip.png | tee out/demo/flip.txt
echo "demo: wrote out/demo/neural.png, out/demo/classical.png and out/demo/flip.png"
