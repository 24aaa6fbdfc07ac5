#!/usr/bin/env bash
# A/B frame times of two nbvh binaries in one run on one GPU (issue 14: each step's measurement):
# hybrid and classical 1920x1080 frames of the default scene and the dragon (and Chess with CHESS=1),
# max depth 8, the models trained once (CUDA defaults of the NEW binary; the model format is shared),
# then per row a warm-up render and OLD, NEW, OLD, NEW (interleaved: clocks and caches drift alike),
# same seed. Reports the fastest of each binary's two renders in ms per sample, per-pass times, and the
# FLIP between the OLD and NEW images (0 when the change is exact). Writes OUT/ab.json, prints a table.
# Usage (GPU machine, after `source .device/env.sh`): scripts/bench/ab_frames.sh OLD NEW OUT
# Env: DRAGON (xz-packed glb, default .device/study/dragon/dragon_vrip.glb.xz), CHESS=1 (also Chess: the
#      paper's camera and environment, lib.sh bench_scene; carry .device/study/chess), SPP (default 16), WIDTH, HEIGHT,
#      TRAIN_ARGS (extra `nbvh train` flags for both models), RENDER_ARGS (extra render flags, both binaries),
#      OLD_TRAIN_ARGS (when set, OLD renders its own models, trained by OLD with these flags: an A/B of
#      training settings; OLD may then be the same binary as NEW), OLD_RENDER_ARGS (extra render flags
#      of OLD only: an A/B of render settings with one binary, e.g. OLD_RENDER_ARGS="--sampler random").
set -euo pipefail
cd "$(dirname "$0")/../.."
source scripts/bench/lib.sh
OLD=$1 NEW=$2 OUT=$3
DRAGON=${DRAGON:-.device/study/dragon/dragon_vrip.glb.xz}
SPP=${SPP:-16}
T=${TMPDIR:-/tmp}/nbvh_ab
mkdir -p "$OUT" "$T"
unpack "$DRAGON" "$T/dragon.glb"
(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader || echo "no nvidia-smi") | tee "$OUT/device.txt"
# shellcheck disable=SC2206
R=(--width "${WIDTH:-1920}" --height "${HEIGHT:-1080}" --max-depth 8 --exposure 0 ${RENDER_ARGS:-})
# shellcheck disable=SC2206
TA=(${TRAIN_ARGS:-})
"$NEW" train default "${TA[@]}" --out "$T/default.nbvh" > "$T/train_default.log" 2>&1
"$NEW" train "$T/dragon.glb" --neural '*' "${TA[@]}" --out "$T/dragon.nbvh" > "$T/train_dragon.log" 2>&1
OLDM=$T # where OLD's models are
if [ -n "${OLD_TRAIN_ARGS+x}" ]; then
  OLDM=$T/old && mkdir -p "$OLDM"
  # shellcheck disable=SC2206
  OTA=(${OLD_TRAIN_ARGS})
  "$OLD" train default "${OTA[@]}" --out "$OLDM/default.nbvh" > "$T/train_default_old.log" 2>&1
  "$OLD" train "$T/dragon.glb" --neural '*' "${OTA[@]}" --out "$OLDM/dragon.nbvh" > "$T/train_dragon_old.log" 2>&1
fi
cp "$T"/train_*.log "$OUT"/
row() { # NAME ARGS... (@M@ in ARGS: the binary's model folder)
  local name=$1; shift
  # Warm-up of both binaries at the measured spp (the same wave buffers); a machine's first renders can
  # still run slow, which the spread check below reports.
  "$OLD" render "${@//@M@/$OLDM}" "${R[@]}" --spp "$SPP" --out "$T/warm.png" > /dev/null 2>&1
  "$NEW" render "${@//@M@/$T}" "${R[@]}" --spp "$SPP" --out "$T/warm.png" > /dev/null 2>&1
  for rep in 1 2; do
    for b in old new; do
      # shellcheck disable=SC2206
      local bin=$OLD m=$OLDM extra=(${OLD_RENDER_ARGS:-}); [ $b = new ] && bin=$NEW m=$T extra=()
      "$bin" render "${@//@M@/$m}" "${R[@]}" "${extra[@]}" --spp "$SPP" --out "$T/${name}_$b.png" \
        --stats "$T/${name}_${b}_$rep.json" > /dev/null 2>&1
    done
  done
  "$NEW" flip "$T/${name}_old.png" "$T/${name}_new.png" 2>&1 | tail -1 > "$T/${name}_flip.txt"
}
row default_classical default --classical
row default_hybrid default --model @M@/default.nbvh
row dragon_classical "$T/dragon.glb" --neural '*' --classical
row dragon_hybrid "$T/dragon.glb" --model @M@/dragon.nbvh
if [ "${CHESS:-0}" = 1 ]; then
  bench_scene chess "$T"
  "$NEW" train "${SRC[@]}" "${NEURAL[@]}" "${TA[@]}" --out "$T/chess.nbvh" > "$T/train_chess.log" 2>&1
  [ -n "${OLD_TRAIN_ARGS+x}" ] && "$OLD" train "${SRC[@]}" "${NEURAL[@]}" "${OTA[@]}" --out "$OLDM/chess.nbvh" \
    > "$T/train_chess_old.log" 2>&1
  cp "$T"/train_chess*.log "$OUT"/
  row chess_classical "${SRC[@]}" "${NEURAL[@]}" --classical "${VIEW[@]}"
  row chess_hybrid "${SRC[@]}" --model @M@/chess.nbvh "${VIEW[@]}"
fi
python3 - "$T" "$OUT/ab.json" "$OLD" "$NEW" <<'PY'
import glob, json, os, re, sys
t, out = sys.argv[1], sys.argv[2]
rows = {}
names = ["default_classical", "default_hybrid", "dragon_classical", "dragon_hybrid", "chess_classical", "chess_hybrid"]
for name in [n for n in names if glob.glob(os.path.join(t, n + "_old_*.json"))]:
    r = {}
    for b in ["old", "new"]:
        runs = [json.load(open(f)) for f in sorted(glob.glob(os.path.join(t, f"{name}_{b}_*.json")))]
        best = min(runs, key=lambda j: j["gpu_total_ms"])
        spp = best["spp"]
        r[b] = {"ms_per_spp": best["gpu_total_ms"] / spp, "all_ms_per_spp": [j["gpu_total_ms"] / spp for j in runs],
                "passes_ms_per_spp": {k.split("/")[-1].replace(".comp", ""): v / spp for k, v in best["pass_gpu_ms"].items()},
                # per bounce, where the binary writes them (since d9e67b5 / aecfd79)
                "passes_ms_per_spp_by_depth": {k.split("/")[-1].replace(".comp", ""): [x / spp for x in v]
                                               for k, v in best.get("pass_gpu_ms_by_depth", {}).items()},
                "rays_per_spp_by_depth": {k: [x / spp for x in v] for k, v in best.get("rays_by_depth", {}).items()},
                "rays_per_second": best["rays_per_second"], "neural": best.get("neural")}
    m = re.search(r"[-+]?\d*\.\d+(?:[eE][-+]?\d+)?|\d+", open(os.path.join(t, f"{name}_flip.txt")).read())
    r["flip_ldr_old_vs_new"] = float(m.group()) if m else None
    r["new_over_old"] = r["new"]["ms_per_spp"] / r["old"]["ms_per_spp"]
    rows[name] = r
for k, r in rows.items():
    # Spread of each binary's renders (slowest / fastest - 1): above 3 % one render was disturbed (a fresh
    # machine's first renders have run 2-3x slow), so the row rests on the other render alone.
    spread = {b: max(r[b]["all_ms_per_spp"]) / min(r[b]["all_ms_per_spp"]) - 1.0 for b in ("old", "new")}
    r["spread"] = spread
    flag = "  UNSTEADY (%s): rerun" % ", ".join("%s %.0f %%" % (b, 100 * v) for b, v in spread.items() if v > 0.03) \
        if max(spread.values()) > 0.03 else ""
    print("%-18s old %6.2f  new %6.2f ms/spp  new/old %.3f  FLIP old vs new %s%s" % (
        k, r["old"]["ms_per_spp"], r["new"]["ms_per_spp"], r["new_over_old"], r["flip_ldr_old_vs_new"], flag))
json.dump({"old": sys.argv[3], "new": sys.argv[4], "old_train_args": os.environ.get("OLD_TRAIN_ARGS"),
           "old_render_args": os.environ.get("OLD_RENDER_ARGS"),
           "train_args": os.environ.get("TRAIN_ARGS", ""), "rows": rows}, open(out, "w"), indent=1)
PY
