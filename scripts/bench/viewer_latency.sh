#!/usr/bin/env bash
# GPU-machine half of results/viewer/ (issue 13): what a viewer setting change and a model swap cost in
# frames, and the viewer's frame (frames in flight, and blocking for comparison) against `nbvh render`'s
# per-sample time, at 1920x1080 on the default scene with the paper-size CUDA model (5 LoDs).
# The model swap re-uploads the same model file loaded a second time (another object: every buffer is
# replaced, the instances marked again).
# Usage (after `source .device/env.sh`): scripts/bench/viewer_latency.sh OUT
# Env: BIN (default .device/viewer/bin: nbvh and nbvh_bench_viewer_latency, stripped).
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$1
BIN=${BIN:-.device/viewer/bin}
T=${TMPDIR:-/tmp}/nbvh_viewer
mkdir -p "$OUT" "$T"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/device.txt"
"$BIN/nbvh" train default --backend cuda --lods 5 --out "$T/default.nbvh" > "$OUT/train.log" 2>&1
tail -3 "$OUT/train.log"
"$BIN/nbvh_bench_viewer_latency" default "$T/default.nbvh" --width 1920 --height 1080 --frames 32 --device gpu \
  --json "$OUT/viewer_latency_h100.json" | tee "$OUT/bench.txt"
