#!/usr/bin/env bash
# The paper's Chess scene (../shared/scenes/abeautifulgame, scene 'scene_neural': 48 neural piece
# instances, 14 assets) with every neural asset from one model, on a GPU machine:
#   train (CUDA) -> converged classical reference (REF_SPP) -> noise floor (classical, other seed, SPP)
#   -> hybrid (SPP) -> LDR-FLIP of both against the reference, frame times, model memory.
# Camera and environment of ../shared/scenes/chess_nbvh/configs (the config's view matrix inverted:
# eye 0.600,0.358,0.179, 45 deg; environment photo_studio_loft_hall (512x256 here, 4k there), rotated
# 285 deg as the config says -- our rotation convention may differ from the official renderer's).
# Usage: scripts/bench/chess.sh SCENE.glb[.xz] ENV.hdr OUT_DIR
#   env: NBVH (binary), SPP, REF_SPP, TRAIN_ARGS (extra nbvh train flags), REF (reuse this reference
#   PNG), NO_CLASSICAL=1 (skip the noise-floor render when REF is reused), EXPOSURE (PNG stops, default 0),
#   MODEL (where the trained model goes, default OUT_DIR/chess.nbvh; a GPU run returns at most 8 files)
# A SCENE ending in .xz (scripts/bench/study_prepare.sh packs it so that it travels) is unpacked to $TMPDIR.
# Writes OUT_DIR/{reference,classical,hybrid,hybrid_flip}.png, *_stats.json, summary.txt.
# On the GPU machine (carry .gl, .device/env.sh, .device/lib, .device/study/bin, .device/study/chess):
#   source .device/env.sh && NBVH=.device/study/bin/nbvh MODEL=/tmp/chess.nbvh SPP=8192 REF_SPP=16384
#   scripts/bench/chess.sh .device/study/chess/abeautifulgame.glb.xz
#   .device/study/chess/photo_studio_loft_hall_512x256.hdr $OUT
set -euo pipefail
SCENE=$1 ENV=$2 OUT=$3
NBVH=${NBVH:-build/app/nbvh}
SPP=${SPP:-1024} REF_SPP=${REF_SPP:-4096}
CAM="0.600,0.358,0.179,-0.197,-0.197,-0.057,45"
mkdir -p "$OUT"
MODEL=${MODEL:-$OUT/chess.nbvh}
if [[ $SCENE == *.xz ]]; then
  source "$(dirname "$0")/lib.sh"
  U="${TMPDIR:-/tmp}/$(basename "${SCENE%.xz}")"
  unpack "$SCENE" "$U"
  SCENE=$U
fi
S="$OUT/summary.txt"
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; echo "train flags: ${TRAIN_ARGS:-(defaults)}";
  echo "spp $SPP, reference ${REF:-$REF_SPP spp}"; } > "$S"
# One fixed exposure (EXPOSURE stops, default 0 as in the committed results) for every PNG that FLIP compares.
R=("$NBVH" render "$SCENE" --camera "$CAM" --env "$ENV" --env-rotation 285 --width 1920 --height 1080 --max-depth 8
   --exposure "${EXPOSURE:-0}")
t0=$(date +%s)
# shellcheck disable=SC2086
"$NBVH" train "$SCENE" --backend cuda ${TRAIN_ARGS:-} --out "$MODEL" 2>&1 | grep -v "^step " >> "$S"
echo "train wall $(( $(date +%s) - t0 )) s" >> "$S"
"$NBVH" info "$MODEL" | grep -v "^  level" >> "$S"
REFPNG=${REF:-$OUT/reference.png}
[ -n "${REF:-}" ] || "${R[@]}" --classical --spp "$REF_SPP" --seed 1 --out "$REFPNG" --stats "$OUT/reference_stats.json" 2>&1 | tail -1 >> "$S"
[ -n "${NO_CLASSICAL:-}" ] || "${R[@]}" --classical --spp "$SPP" --seed 2 --out "$OUT/classical.png" --stats "$OUT/classical_stats.json" 2>&1 | tail -1 >> "$S"
"${R[@]}" --model "$MODEL" --spp "$SPP" --seed 2 --out "$OUT/hybrid.png" --stats "$OUT/hybrid_stats.json" 2>&1 | tail -2 >> "$S"
{
  [ -n "${NO_CLASSICAL:-}" ] || echo "noise floor (classical seed 2 vs reference): $("$NBVH" flip "$REFPNG" "$OUT/classical.png")"
  echo "hybrid vs reference: $("$NBVH" flip "$REFPNG" "$OUT/hybrid.png" --heatmap "$OUT/hybrid_flip.png")"
} >> "$S"
tail -4 "$S"
