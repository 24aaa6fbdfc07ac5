#!/usr/bin/env bash
# GPU-machine half of the study (issue 11): one scene's default sweep with `nbvh study`, results in OUT.
# Usage (after `source .device/env.sh`): scripts/bench/study.sh default|dragon|chess OUT [extra nbvh study flags]
# Env: NBVH (binary, default .device/study/bin/nbvh), NODES, HASH, LODS, CAMERAS (sweep), WIDTH, HEIGHT, SPP,
#      REF_SPP (compared images and reference), BUDGET (minutes; configurations that would end later are
#      not started and are listed in study.json), BACKEND (cuda), DEVICE (gpu), TIME_WIDTH, TIME_HEIGHT.
# The sweep: nodes 1000,2395,8000 x hash 2^14,2^16,2^18, 3 LoDs each (+ the LoD switch), 3 cameras, images
# 960x540 at 1024 spp against an 8192-spp classical reference, frame times at 1920x1080, 4 spp, median of 3;
# equal-memory decimation and equal-time classical baselines; the raised leaf budget (64) on the middle
# configuration. Writes OUT/study.json, study.csv, camera 0's reference / hybrid / decimated PNGs and log.txt.
# Plots and table afterwards, on the build machine: scripts/bench/plot_study.py OUT/study.json results/study/SCENE
set -euo pipefail
cd "$(dirname "$0")/../.."
WHICH=$1 OUT=$2
shift 2
NBVH=${NBVH:-.device/study/bin/nbvh}
mkdir -p "$OUT"
TMP=${TMPDIR:-/tmp}/nbvh_study
mkdir -p "$TMP"
source scripts/bench/lib.sh
if [ ! -x "$NBVH" ] && [ -f "$NBVH.xz" ]; then # a carried, xz-packed binary
  unpack "$NBVH.xz" "$TMP/nbvh.$$" && chmod +x "$TMP/nbvh.$$" && NBVH=$TMP/nbvh.$$ # per process: parts run in parallel
fi
case "$WHICH" in
  default) SCENE=(default) ;;
  dragon) # NBVH_STUDY_UNPACKED=1 (study_multi.sh): unpacked once before the parallel parts
    [ "${NBVH_STUDY_UNPACKED:-0}" = 1 ] || unpack .device/study/dragon/dragon_vrip.glb.xz "$TMP/dragon_vrip.glb"
    SCENE=("$TMP/dragon_vrip.glb" --neural '*') ;;
  chess)
    # The paper's camera and environment (scripts/bench/chess.sh): 48 neural pieces, 14 assets, one model.
    [ "${NBVH_STUDY_UNPACKED:-0}" = 1 ] || unpack .device/study/chess/abeautifulgame.glb.xz "$TMP/abeautifulgame.glb"
    SCENE=("$TMP/abeautifulgame.glb" --camera 0.600,0.358,0.179,-0.197,-0.197,-0.057,45
           --env .device/study/chess/photo_studio_loft_hall_512x256.hdr --env-rotation 285 --exposure 0) ;;
  *) echo "study.sh: scene must be default, dragon or chess" >&2; exit 2 ;;
esac
{
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || echo "no nvidia-smi"
  "$NBVH" study "${SCENE[@]}" --out "$OUT" --backend "${BACKEND:-cuda}" --device "${DEVICE:-gpu}" \
    --nodes "${NODES:-1000,2395,8000}" --hash-log2 "${HASH:-14,16,18}" --lods "${LODS:-3}" --cameras "${CAMERAS:-3}" \
    --width "${WIDTH:-960}" --height "${HEIGHT:-540}" --spp "${SPP:-1024}" --ref-spp "${REF_SPP:-8192}" \
    --time-width "${TIME_WIDTH:-1920}" --time-height "${TIME_HEIGHT:-1080}" --time-spp 4 --repeat 3 --max-depth 8 \
    --budget-minutes "${BUDGET:-9.5}" --save-images "$@"
} 2>&1 | tee "$OUT/log.txt"
