#!/usr/bin/env bash
# GPU-machine run of `nbvh converge` (issue 11: is the study's shared-seed FLIP the converged one?): for
# each scene, the model `nbvh train` makes by default (CUDA), then hybrid and classical images of one seed
# extended from FROM to SPP samples against a REF_SPP classical reference, at the study's image size
# (960x540, max depth 8) and camera 0 (the scene's own, the dragon auto-framed, Chess the paper's).
# Usage (after `source .device/env.sh`): scripts/bench/converge.sh OUT [default] [dragon] [chess]
# Env: NBVH (binary, default .device/study/bin/nbvh, xz-packed allowed), FROM (128), SPP (8192),
#      REF_SPP (32768), WIDTH x HEIGHT (960 x 540), BACKEND (cuda), DEVICE (gpu), TRAIN_ARGS (extra nbvh
#      train flags), SAMPLERS (sobol; e.g. "sobol random": one model, one run per --sampler). Writes
#      OUT/SCENE.json and OUT/SCENE.csv (OUT/SCENE_random.* for --sampler random) and OUT/log.txt.
# A dry run on the build machine: BACKEND=cpu DEVICE=cpu WIDTH=32 HEIGHT=18 FROM=1 SPP=2 REF_SPP=4
#      TRAIN_ARGS="--steps 20 --batch 256 --nodes 63" NBVH=build/app/nbvh scripts/bench/converge.sh OUT default
# Measured on the H100 (2026-11-26, results/study/convergence/log.txt): 124 + 151 + 90 = 365 s for the three scenes.
# Plot afterwards, on the build machine: scripts/bench/plot_convergence.py OUT/*.json results/study/convergence/convergence.png
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$1
shift
SCENES=("$@")
[ ${#SCENES[@]} -gt 0 ] || SCENES=(default dragon chess)
NBVH=${NBVH:-.device/study/bin/nbvh}
mkdir -p "$OUT"
TMP=${TMPDIR:-/tmp}/nbvh_converge
mkdir -p "$TMP"
source scripts/bench/lib.sh
if [ ! -x "$NBVH" ] && [ -f "$NBVH.xz" ]; then
  unpack "$NBVH.xz" "$TMP/nbvh" && chmod +x "$TMP/nbvh" && NBVH=$TMP/nbvh
fi
{
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || echo "no nvidia-smi"
  for WHICH in "${SCENES[@]}"; do
    case "$WHICH" in
      default) SCENE=(default); VIEW=() ;;
      dragon)
        unpack .device/study/dragon/dragon_vrip.glb.xz "$TMP/dragon_vrip.glb"
        SCENE=("$TMP/dragon_vrip.glb"); VIEW=() ;;
      chess)
        unpack .device/study/chess/abeautifulgame.glb.xz "$TMP/abeautifulgame.glb"
        SCENE=("$TMP/abeautifulgame.glb")
        VIEW=(--camera 0.600,0.358,0.179,-0.197,-0.197,-0.057,45 --env .device/study/chess/photo_studio_loft_hall_512x256.hdr
              --env-rotation 285 --exposure 0) ;;
      *) echo "converge.sh: scene must be default, dragon or chess" >&2; exit 2 ;;
    esac
    NEURAL=()
    [ "$WHICH" = dragon ] && NEURAL=(--neural '*')
    echo "== $WHICH"
    t0=$(date +%s)
    # shellcheck disable=SC2086
    "$NBVH" train "${SCENE[@]}" "${NEURAL[@]}" --backend "${BACKEND:-cuda}" ${TRAIN_ARGS:-} --out "$TMP/$WHICH.nbvh" 2>&1 \
      | grep -v "^step " | tail -3
    for SAMPLER in ${SAMPLERS:-sobol}; do
      NAME=$WHICH
      [ "$SAMPLER" = sobol ] || NAME=${WHICH}_$SAMPLER
      echo "-- --sampler $SAMPLER"
      "$NBVH" converge "${SCENE[@]}" --model "$TMP/$WHICH.nbvh" "${VIEW[@]}" --device "${DEVICE:-gpu}" \
        --width "${WIDTH:-960}" --height "${HEIGHT:-540}" --sampler "$SAMPLER" \
        --max-depth 8 --from "${FROM:-128}" --spp "${SPP:-8192}" --ref-spp "${REF_SPP:-32768}" \
        --json "$OUT/$NAME.json" --csv "$OUT/$NAME.csv"
    done
    echo "$WHICH: $(( $(date +%s) - t0 )) s"
  done
} 2>&1 | tee "$OUT/log.txt"
