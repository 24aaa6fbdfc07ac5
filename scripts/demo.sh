#!/usr/bin/env bash
# Installs, builds and runs the demo on the built-in default scene; results land in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out/demo
build/app/nbvh render default --out out/demo/classical.png --stats out/demo/classical_stats.json
echo "demo: wrote out/demo/classical.png"
