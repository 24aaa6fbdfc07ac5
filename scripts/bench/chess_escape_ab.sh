#!/usr/bin/env bash
# Back-face escape A/B on Chess (the paper's camera and environment, scripts/bench/chess.sh), one GPU call:
# the default model trained in the call, then at 960x540 2048 spp a classical reference (seed 7), a
# classical render (seed 0: the floor) and the hybrid with --neural-backface-escape off and on (seed 0),
# their FLIPs (OUT/flips.txt), and 1080p 16-spp frame times of both, 2 interleaved rounds (OUT/*.json).
# Usage (GPU machine, after `source .device/env.sh`; carry .device/study/chess): scripts/bench/chess_escape_ab.sh OUT
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$1; B=${NBVH:-.device/study/bin/nbvh}; T=${TMPDIR:-/tmp}/nbvh_chess_ab
mkdir -p "$OUT" "$T"
python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' \
  .device/study/chess/abeautifulgame.glb.xz "$T/chess.glb"
S=("$T/chess.glb" --camera 0.600,0.358,0.179,-0.197,-0.197,-0.057,45
   --env .device/study/chess/photo_studio_loft_hall_512x256.hdr --env-rotation 285 --exposure 0)
"$B" train "$T/chess.glb" --out "$T/chess.nbvh" > "$OUT/train.log" 2>&1
R=(--width 960 --height 540 --max-depth 8 --spp "${FLIP_SPP:-2048}")
"$B" render "${S[@]}" --classical "${R[@]}" --seed 7 --out "$T/ref.png" > /dev/null 2>&1
"$B" render "${S[@]}" --classical "${R[@]}" --out "$T/cl.png" > /dev/null 2>&1
line="chess floor $("$B" flip "$T/ref.png" "$T/cl.png" | tail -1)"
for v in off on; do
  "$B" render "${S[@]}" --model "$T/chess.nbvh" --neural-backface-escape $v "${R[@]}" --out "$T/$v.png" > /dev/null 2>&1
  line="$line | $v: vs ref $("$B" flip "$T/ref.png" "$T/$v.png" | tail -1), vs classical (same seed) $("$B" flip "$T/cl.png" "$T/$v.png" | tail -1)"
done
echo "$line" | tee "$OUT/flips.txt"
F=(--width 1920 --height 1080 --max-depth 8 --spp 16)
"$B" render "${S[@]}" --model "$T/chess.nbvh" "${F[@]}" --out "$T/warm.png" > /dev/null 2>&1
for rep in 1 2; do
  "$B" render "${S[@]}" --classical "${F[@]}" --out "$T/f.png" --stats "$OUT/classical_$rep.json" > /dev/null 2>&1
  for v in off on; do
    "$B" render "${S[@]}" --model "$T/chess.nbvh" --neural-backface-escape $v "${F[@]}" --out "$T/f.png" \
      --stats "$OUT/${v}_$rep.json" > /dev/null 2>&1
  done
done
python3 - "$OUT" <<'PY'
import glob, json, os, sys
for v in ("classical", "off", "on"):
    ms = [json.load(open(f))["gpu_total_ms"] / 16 for f in sorted(glob.glob(os.path.join(sys.argv[1], v + "_[0-9].json")))]
    print("%-9s ms per sample %s" % (v, " ".join("%.3f" % m for m in ms)))
PY
