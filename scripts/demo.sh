#!/usr/bin/env bash
# Installs, builds and runs the demo on the built-in default scene; results land in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out/demo
# Train the default scene's neural asset (CUDA when a GPU is usable, else the CPU backend: ~1-2 min on 2 cores).
build/app/nbvh train default --out out/demo/default.nbvh --log out/demo/train_log.csv
build/app/nbvh render default --out out/demo/classical.png --stats out/demo/classical_stats.json
echo "demo: wrote out/demo/classical.png"
