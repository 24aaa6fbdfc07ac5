#!/usr/bin/env bash
# The paper's Chess scene (../shared/scenes/abeautifulgame, scene 'scene_neural': 48 neural piece
# instances) with every neural asset from one model, on a GPU machine:
#   train (CUDA) -> converged classical reference (REF_SPP) -> noise floor (classical, other seed, SPP)
#   -> hybrid (SPP) -> LDR-FLIP of both against the reference, frame times, model memory.
# Camera and environment of ../shared/scenes/chess_nbvh/configs (the config's view matrix inverted:
# eye 0.600,0.358,0.179, 45 deg; environment photo_studio_loft_hall (512x256 here, 4k there), rotated
# 285 deg as the config says -- our rotation convention may differ from the official renderer's).
# Usage: scripts/bench/chess.sh SCENE.glb ENV.hdr OUT_DIR   (env: NBVH, NODES, SPP, REF_SPP, TRAIN_ARGS)
set -euo pipefail
SCENE=$1 ENV=$2 OUT=$3
NBVH=${NBVH:-build/app/nbvh}
SPP=${SPP:-1024} REF_SPP=${REF_SPP:-4096}
CAM="0.600,0.358,0.179,-0.197,-0.197,-0.057,45"
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/device.txt"
git rev-parse HEAD 2>/dev/null | tee -a "$OUT/device.txt" || true
R=("$NBVH" render "$SCENE" --camera "$CAM" --env "$ENV" --env-rotation 285 --width 1920 --height 1080 --max-depth 8)
t0=$(date +%s)
"$NBVH" train "$SCENE" --backend cuda ${NODES:+--nodes $NODES} ${TRAIN_ARGS:-} --out "$OUT/chess.nbvh" \
    --log "$OUT/train_log.csv" 2>&1 | grep -v "^step " | tee "$OUT/train.txt"
echo "train wall $(( $(date +%s) - t0 )) s" | tee -a "$OUT/train.txt"
"$NBVH" info "$OUT/chess.nbvh" > "$OUT/info.txt"
"${R[@]}" --classical --spp "$REF_SPP" --seed 1 --out "$OUT/reference.png" --stats "$OUT/reference_stats.json" 2>&1 | tail -2
"${R[@]}" --classical --spp "$SPP" --seed 2 --out "$OUT/classical.png" --stats "$OUT/classical_stats.json" 2>&1 | tail -2
"${R[@]}" --model "$OUT/chess.nbvh" --spp "$SPP" --seed 2 --out "$OUT/hybrid.png" --stats "$OUT/hybrid_stats.json" 2>&1 | tail -3
{
  echo "noise floor (classical seed 2 vs reference): $("$NBVH" flip "$OUT/reference.png" "$OUT/classical.png")"
  echo "hybrid vs reference: $("$NBVH" flip "$OUT/reference.png" "$OUT/hybrid.png" --heatmap "$OUT/hybrid_flip.png")"
} | tee "$OUT/flip.txt"
