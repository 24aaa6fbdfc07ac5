#!/usr/bin/env bash
# GPU-machine half of the frame-time measurement of results/perf/ (issue 14): classical and hybrid frames
# of the default scene and the dragon at 1920x1080, max depth 8, with the per-pass GPU times and ray
# counts of `nbvh render --stats`. Each render runs once untimed first (the GPU's clocks ramp up over
# the first ~0.3 s of work: without it the first hybrid renders of a run read up to 1.9x slow).
# Usage (after `source .device/env.sh`): scripts/bench/frame_perf.sh OUT
# Env: NBVH (default .device/study/bin/nbvh), DRAGON (xz-packed glb, default .device/study/dragon/dragon_vrip.glb.xz),
#      SPP (default 16).
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$1
NBVH=${NBVH:-.device/study/bin/nbvh}
DRAGON=${DRAGON:-.device/study/dragon/dragon_vrip.glb.xz}
SPP=${SPP:-16}
T=${TMPDIR:-/tmp}/nbvh_perf
mkdir -p "$OUT" "$T"
python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' "$DRAGON" "$T/dragon.glb"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/device.txt"
R=(--width 1920 --height 1080 --spp "$SPP" --max-depth 8 --exposure 0)
# Models: the default `nbvh train` (one LoD) and three LoDs for the secondary-LoD rows.
"$NBVH" train default --out "$T/default.nbvh" > "$OUT/train_default.log" 2>&1
"$NBVH" train default --lods 3 --out "$T/default_lods3.nbvh" > "$OUT/train_default_lods3.log" 2>&1
"$NBVH" train "$T/dragon.glb" --neural '*' --out "$T/dragon.nbvh" > "$OUT/train_dragon.log" 2>&1
"$NBVH" train "$T/dragon.glb" --neural '*' --lods 3 --out "$T/dragon_lods3.nbvh" > "$OUT/train_dragon_lods3.log" 2>&1
row() { # NAME ARGS...: warm-up render, then the measured one
  local name=$1; shift
  "$NBVH" render "$@" "${R[@]}" --spp 4 --out "$T/warm.png" > /dev/null 2>&1
  "$NBVH" render "$@" "${R[@]}" --out "$T/$name.png" --stats "$T/$name.json" 2>&1 | grep -E "GPU|truncated" | sed "s/^/$name: /"
}
row default_classical default --classical
row default_hybrid default --model "$T/default.nbvh"
row default_hybrid_lods3_lod0 default --model "$T/default_lods3.nbvh"
row default_hybrid_lods3_secondary2 default --model "$T/default_lods3.nbvh" --secondary-lod 2
row dragon_classical "$T/dragon.glb" --neural '*' --classical
row dragon_hybrid "$T/dragon.glb" --model "$T/dragon.nbvh"
row dragon_hybrid_lods3_secondary2 "$T/dragon.glb" --model "$T/dragon_lods3.nbvh" --secondary-lod 2
python3 - "$T" "$OUT/frames.json" <<'PY'
import json, glob, os, sys
rows = {}
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    j = json.load(open(f)); spp = j["spp"]
    rows[os.path.basename(f)[:-5]] = {
        "ms_per_spp": j["gpu_total_ms"] / spp,
        "passes_ms_per_spp": {k.split("/")[-1].replace(".comp", ""): v / spp for k, v in j["pass_gpu_ms"].items()},
        "rays_per_second": j["rays_per_second"], "rays": j["rays"], "neural": j.get("neural")}
json.dump(rows, open(sys.argv[2], "w"), indent=1)
for k, r in rows.items():
    n = r["neural"] or {}
    print("%-34s %6.2f ms/spp  %.3g rays/s  %s" % (k, r["ms_per_spp"], r["rays_per_second"],
          "queries/ray %.2f, %.3g queries/s, leaf-cap rays %s" % (n["queries_per_ray"], n["queries_per_second"], n.get("leaf_cap_rays")) if n else ""))
PY
