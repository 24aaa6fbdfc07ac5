#!/usr/bin/env bash
# Frame times of render-flag variants of one binary in one GPU call (issue 14): the scenes of SCENES (default:
# the default scene and the dragon; chess too), models trained once by the binary's default `nbvh train`,
# then per scene a warm-up and REPS
# interleaved rounds over the variants (clocks and caches drift alike), 1920x1080, 16 spp, max depth 8,
# same seed. Reports the fastest render of each variant in ms per sample, per-pass times, and the FLIP
# of each variant's image against the first variant's. Writes OUT/sweep.json and prints a table.
# Usage (GPU machine, after `source .device/env.sh`):
#   VARIANTS=$'base|\ntail3|--neural-tail-depth 3' scripts/bench/flag_sweep.sh OUT
# Env: NBVH (binary, default .device/study/bin/nbvh), VARIANTS (lines NAME|FLAGS: hybrid flags, or
#      "classical FLAGS" for a classical variant; the classical render of each scene with no flags is
#      always added as "classical"; FLIP compares each variant with the first), REPS (default 2), SPP (16),
#      SCENES (default "default dragon"; chess needs .device/study/chess carried), DRAGON (xz-packed glb,
#      default .device/study/dragon/dragon_vrip.glb.xz), WIDTH, HEIGHT,
#      TRAIN_ARGS (extra `nbvh train` flags, e.g. a short CPU training for a dry run), MAX_DEPTH (8).
set -euo pipefail
cd "$(dirname "$0")/../.."
source scripts/bench/lib.sh
OUT=$1
bench_setup "$OUT" sweep
# shellcheck disable=SC2206
TA=(${TRAIN_ARGS:-})
# shellcheck disable=SC2206
SC=(${SCENES:-default dragon})
for scene in "${SC[@]}"; do
  bench_scene "$scene" "$T"
  "$B" train "${SRC[@]}" "${NEURAL[@]}" "${TA[@]}" --out "$T/$scene.nbvh" > "$OUT/train_$scene.log" 2>&1
done
R=(--width "${WIDTH:-1920}" --height "${HEIGHT:-1080}" --max-depth "${MAX_DEPTH:-8}" --exposure 0 --spp "${SPP:-16}")
mapfile -t V <<< "${VARIANTS:?VARIANTS: lines NAME|FLAGS}"
for scene in "${SC[@]}"; do
  bench_scene "$scene" "$T"
  S=("${SRC[@]}" "${VIEW[@]}"); C=("${NEURAL[@]}" --classical)
  "$B" render "${S[@]}" --model "$T/$scene.nbvh" "${R[@]}" --out "$T/warm.png" > /dev/null 2>&1
  for rep in $(seq "${REPS:-2}"); do
    "$B" render "${S[@]}" "${C[@]}" "${R[@]}" --out "$T/${scene}_classical.png" --stats "$OUT/${scene}_classical_$rep.json" > /dev/null 2>&1
    for v in "${V[@]}"; do
      name=${v%%|*}
      # shellcheck disable=SC2206
      F=(${v#*|})
      M=(--model "$T/$scene.nbvh")
      if [ "${F[0]:-}" = classical ]; then M=("${C[@]}"); F=("${F[@]:1}"); fi # a classical variant
      "$B" render "${S[@]}" "${M[@]}" "${F[@]}" "${R[@]}" --out "$T/${scene}_$name.png" \
        --stats "$OUT/${scene}_${name}_$rep.json" > "$T/log" 2>&1 || { echo "FAIL $scene $name"; tail -2 "$T/log"; }
    done
  done
  first=${V[0]%%|*}
  for v in "${V[@]}"; do
    name=${v%%|*}
    "$B" flip "$T/${scene}_$first.png" "$T/${scene}_$name.png" 2>&1 | tail -1 > "$OUT/${scene}_${name}_flip.txt"
  done
done
python3 - "$OUT" <<'PY'
import glob, json, os, re, sys
out = sys.argv[1]
rows = {}
for f in sorted(glob.glob(os.path.join(out, "*_[0-9].json"))):
    key = os.path.basename(f).rsplit("_", 1)[0]
    rows.setdefault(key, []).append(json.load(open(f)))
summary = {}
for key, runs in rows.items():
    best = min(runs, key=lambda j: j["gpu_total_ms"])
    spp = best["spp"]
    flip = None
    ff = os.path.join(out, key + "_flip.txt")
    if os.path.exists(ff):
        m = re.search(r"[-+]?\d*\.\d+(?:[eE][-+]?\d+)?|\d+", open(ff).read())
        flip = float(m.group()) if m else None
    summary[key] = {"ms_per_spp": best["gpu_total_ms"] / spp, "all_ms_per_spp": [j["gpu_total_ms"] / spp for j in runs],
                    "passes_ms_per_spp": {k.split("/")[-1].replace(".comp", ""): v / spp for k, v in best["pass_gpu_ms"].items()},
                    "passes_ms_per_spp_by_depth": {k.split("/")[-1].replace(".comp", ""): [x / spp for x in v]
                                                   for k, v in best.get("pass_gpu_ms_by_depth", {}).items()},
                    "rays_per_second": best["rays_per_second"], "neural": best.get("neural"), "flip_vs_first": flip}
json.dump({"variants": os.environ.get("VARIANTS"), "rows": summary}, open(os.path.join(out, "sweep.json"), "w"), indent=1)
for key, r in sorted(summary.items()):
    scene = key.split("_")[0]
    c = summary.get(scene + "_classical", {}).get("ms_per_spp")
    print("%-28s %6.3f ms/spp  %5.2fx classical  FLIP vs first %s" % (key, r["ms_per_spp"], r["ms_per_spp"] / c if c else 0, r["flip_vs_first"]))
PY
