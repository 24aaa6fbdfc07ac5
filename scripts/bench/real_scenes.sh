#!/usr/bin/env bash
# The shared real scenes beyond the study's three (results/scenes/): every mesh made neural with the
# model `nbvh train --neural '*'` makes by default, then per scene its noise floor, independent and
# shared-seed FLIP from FROM to SPP samples against a REF_SPP classical reference (`nbvh converge`, 960x540,
# the scene's own or automatic camera), classical and hybrid frame times (1920x1080, 16 spp, REPS
# interleaved rounds, `--stats`), and 960x540 PNGs of both (IMG_SPP samples) to look at.
# Prepare on the build machine (FOLDER ignored, e.g. .device/scenes; carry FOLDER, .gl, .device/env.sh,
# .device/lib, .device/study/bin; the carry + tree stay under 64 MiB):
#   for s in stanford_bunny flight_helmet sheen_cloth smithsonian_usnm1145291 balloon; do
#     (cd ../shared/scenes && tar cf - $s) | xz > FOLDER/$s.tar.xz; done
# Run (GPU machine): source .device/env.sh && scripts/bench/real_scenes.sh FOLDER OUT
# Env: NBVH (default .device/study/bin/nbvh), FROM (256), SPP (2048), REF_SPP (8192), WIDTH x HEIGHT
#      (960 x 540), TW x TH (1920 x 1080), TSPP (16), REPS (2), IMG_SPP (512), BACKEND (cuda), DEVICE (gpu),
#      TRAIN_ARGS (extra train flags). Writes OUT/SCENE/{train.log,info.txt,converge.json,
#      classical_R.json,hybrid_R.json,classical.png,hybrid.png} and OUT/summary.txt.
# Dry run on the build machine (lavapipe, tiny CPU models): BACKEND=cpu DEVICE=cpu WIDTH=48 HEIGHT=27 TW=48 TH=27
#      FROM=1 SPP=2 REF_SPP=4 TSPP=1 REPS=1 IMG_SPP=2 TRAIN_ARGS="--steps 20 --batch 256 --nodes 63"
#      NBVH=build/app/nbvh scripts/bench/real_scenes.sh FOLDER OUT
set -euo pipefail
cd "$(dirname "$0")/../.."
DIR=${1:?usage: real_scenes.sh FOLDER OUT}
OUT=${2:?usage: real_scenes.sh FOLDER OUT}
B=${NBVH:-.device/study/bin/nbvh}
source scripts/bench/lib.sh
T=${TMPDIR:-/tmp}/nbvh_real_scenes
mkdir -p "$OUT" "$T"
for f in "$DIR"/*.tar.xz; do unpack "$f" "$T/pack.tar" && tar xf "$T/pack.tar" -C "$T"; done
(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || echo "no nvidia-smi") | tee "$OUT/device.txt"
DEV=(--device "${DEVICE:-gpu}")
# shellcheck disable=SC2206
TA=(${TRAIN_ARGS:-})
: > "$OUT/summary.txt"
for f in stanford_bunny/stanford_bunny.glb smithsonian_usnm1145291/usnm_1145291.glb sheen_cloth/SheenCloth.gltf \
         flight_helmet/FlightHelmet.gltf balloon/scene.gltf; do
  [ -f "$T/$f" ] || { echo "real_scenes.sh: $f not packed, left out" | tee -a "$OUT/summary.txt"; continue; }
  name=${f%%/*}
  S="$T/$f"
  O="$OUT/$name"
  mkdir -p "$O"
  t0=$(date +%s)
  "$B" train "$S" --neural '*' --backend "${BACKEND:-cuda}" "${TA[@]}" --out "$T/$name.nbvh" 2>&1 | grep -v "^step " > "$O/train.log" \
    || { echo "$name: training failed: $(tail -1 "$O/train.log")" | tee -a "$OUT/summary.txt"; continue; }
  "$B" info "$T/$name.nbvh" > "$O/info.txt" 2>&1 || true
  "$B" converge "$S" --model "$T/$name.nbvh" "${DEV[@]}" --width "${WIDTH:-960}" --height "${HEIGHT:-540}" \
    --from "${FROM:-256}" --spp "${SPP:-2048}" --ref-spp "${REF_SPP:-8192}" --json "$O/converge.json" > "$O/converge.log" 2>&1 \
    || echo "$name: converge failed: $(tail -1 "$O/converge.log")" | tee -a "$OUT/summary.txt"
  R=("${DEV[@]}" --width "${TW:-1920}" --height "${TH:-1080}" --spp "${TSPP:-16}" --exposure 0)
  for rep in $(seq "${REPS:-2}"); do
    "$B" render "$S" --neural '*' --classical "${R[@]}" --out "$T/c.png" --stats "$O/classical_$rep.json" > /dev/null 2>&1 || echo "$name: classical render failed"
    "$B" render "$S" --model "$T/$name.nbvh" "${R[@]}" --out "$T/h.png" --stats "$O/hybrid_$rep.json" > /dev/null 2>&1 || echo "$name: hybrid render failed"
  done
  I=("${DEV[@]}" --width "${WIDTH:-960}" --height "${HEIGHT:-540}" --spp "${IMG_SPP:-512}")
  # Both images at the reference's exposure (converge.json), as the FLIPs see them.
  stops=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["exposure_stops"])' "$O/converge.json" 2>/dev/null || echo auto)
  "$B" render "$S" --neural '*' --classical "${I[@]}" --exposure "$stops" --out "$O/classical.png" > /dev/null 2>&1 || echo "$name: classical image failed"
  "$B" render "$S" --model "$T/$name.nbvh" "${I[@]}" --exposure "$stops" --out "$O/hybrid.png" > /dev/null 2>&1 || echo "$name: hybrid image failed"
  echo "$name: $(( $(date +%s) - t0 )) s" | tee -a "$OUT/summary.txt"
done
python3 - "$OUT" <<'PY' | tee -a "$OUT/summary.txt"
import glob, json, os, sys
out = sys.argv[1]
for d in sorted(glob.glob(os.path.join(out, "*/"))):
    name = os.path.basename(d.rstrip("/"))
    def best(kind):
        runs = [json.load(open(f)) for f in sorted(glob.glob(os.path.join(d, kind + "_[0-9].json")))]
        return min((r["gpu_total_ms"] / r["spp"] for r in runs), default=None), (runs[0] if runs else {})
    c, _ = best("classical")
    h, hr = best("hybrid")
    line = f"{name}: classical {c:.3f} ms/spp, hybrid {h:.3f} ms/spp ({h / c:.2f}x)" if c and h else f"{name}: no frame times"
    n = hr.get("neural") or {}
    if n: line += f", {n.get('queries_per_ray', 0):.3f} queries/ray"
    cj = os.path.join(d, "converge.json")
    if os.path.exists(cj):
        rows = json.load(open(cj)).get("rows", [])
        if rows:
            r = rows[-1]
            line += "; at %s spp: floor %.4f, FLIP %.4f, shared seed %.4f" % (r["spp"], r["noise_floor"], r["flip"], r["flip_same_seed"])
    print(line)
PY
