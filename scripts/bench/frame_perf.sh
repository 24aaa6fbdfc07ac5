#!/usr/bin/env bash
# GPU-machine half of the frame-time measurement of results/perf/ (issue 14): classical and hybrid frames
# of the default scene and the dragon at 1920x1080, max depth 8, with the per-pass GPU times, the same
# per bounce, and the rays per bounce of `nbvh render --stats`: the time per ray of every pass at every
# bounce. Each render runs once untimed first (the GPU's clocks ramp up over the first ~0.3 s of work:
# without it the first hybrid renders of a run read up to 1.9x slow).
# Models: the default `nbvh train` (3 LoDs; rendered with its default coarsest LoD after the first hit,
# and with --secondary-lod same) and `--lods 1` (the official code's single cut).
# Usage (after `source .device/env.sh`): scripts/bench/frame_perf.sh OUT
# Env: NBVH (default .device/study/bin/nbvh), DRAGON (xz-packed glb, default .device/study/dragon/dragon_vrip.glb.xz;
#      NO_DRAGON=1 skips it), SPP (16), WIDTH x HEIGHT (1920 x 1080), DEVICE (auto), TRAIN_ARGS (extra nbvh
#      train flags). Writes OUT/frames.json (per row: ms per spp, per pass, per pass and bounce, rays per
#      bounce, ns per ray per pass and bounce) and prints a summary.
# A dry run on the build machine: NO_DRAGON=1 DEVICE=cpu WIDTH=32 HEIGHT=18 SPP=2
#      TRAIN_ARGS="--backend cpu --steps 20 --batch 256 --nodes 63" NBVH=build/app/nbvh scripts/bench/frame_perf.sh OUT
set -euo pipefail
cd "$(dirname "$0")/../.."
source scripts/bench/lib.sh
OUT=$1
NBVH=${NBVH:-.device/study/bin/nbvh}
DRAGON=${DRAGON:-.device/study/dragon/dragon_vrip.glb.xz}
SPP=${SPP:-16}
T=${TMPDIR:-/tmp}/nbvh_perf
mkdir -p "$OUT" "$T"
rm -f "$T"/*.json
(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || echo "no nvidia-smi") | tee "$OUT/device.txt"
R=(--width "${WIDTH:-1920}" --height "${HEIGHT:-1080}" --max-depth 8 --exposure 0 --device "${DEVICE:-auto}")
train() { # OUT.nbvh LOG SCENE ARGS...
  local model=$1 log=$2; shift 2
  # shellcheck disable=SC2086
  "$NBVH" train "$@" ${TRAIN_ARGS:-} --out "$model" > "$log" 2>&1
}
row() { # NAME ARGS...: warm-up render, then the measured one
  local name=$1; shift
  "$NBVH" render "$@" "${R[@]}" --spp 4 --out "$T/warm.png" > /dev/null 2>&1
  "$NBVH" render "$@" "${R[@]}" --spp "$SPP" --out "$T/$name.png" --stats "$T/$name.json" 2>&1 \
    | { grep -E "GPU|truncated" || true; } | sed "s/^/$name: /"
}
train "$T/default.nbvh" "$OUT/train_default.log" default
train "$T/default_lods1.nbvh" "$OUT/train_default_lods1.log" default --lods 1
row default_classical default --classical
row default_hybrid default --model "$T/default.nbvh"
row default_hybrid_secondary_same default --model "$T/default.nbvh" --secondary-lod same
row default_hybrid_lods1 default --model "$T/default_lods1.nbvh"
if [ -z "${NO_DRAGON:-}" ]; then
  unpack "$DRAGON" "$T/dragon.glb"
  train "$T/dragon.nbvh" "$OUT/train_dragon.log" "$T/dragon.glb" --neural '*'
  train "$T/dragon_lods1.nbvh" "$OUT/train_dragon_lods1.log" "$T/dragon.glb" --neural '*' --lods 1
  row dragon_classical "$T/dragon.glb" --neural '*' --classical
  row dragon_hybrid "$T/dragon.glb" --model "$T/dragon.nbvh"
  row dragon_hybrid_lods1 "$T/dragon.glb" --model "$T/dragon_lods1.nbvh"
fi
python3 - "$T" "$OUT/frames.json" <<'PY'
import json, glob, os, sys
SHADOW = ("shadow", "neural_shadow")  # passes over shadow rays; the others run over path rays
rows = {}
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    j = json.load(open(f)); spp = j["spp"]
    short = lambda k: k.split("/")[-1].replace(".comp", "")
    by_depth = {short(k): v for k, v in j.get("pass_gpu_ms_by_depth", {}).items()}
    rays = j.get("rays_by_depth", {"path": [], "shadow": []})
    ns_per_ray = {}
    for p, ms in by_depth.items():
        counts = rays["shadow" if p in SHADOW else "path"]
        ns_per_ray[p] = [ms[d] * 1e6 / counts[d] if d < len(counts) and counts[d] else None for d in range(len(ms))]
    rows[os.path.basename(f)[:-5]] = {
        "ms_per_spp": j["gpu_total_ms"] / spp,
        "passes_ms_per_spp": {short(k): v / spp for k, v in j["pass_gpu_ms"].items()},
        "passes_ms_per_spp_by_depth": {p: [x / spp for x in v] for p, v in by_depth.items()},
        "rays_per_spp_by_depth": {k: [x / spp for x in v] for k, v in rays.items()},
        "ns_per_ray_by_depth": ns_per_ray,
        "rays_per_second": j["rays_per_second"], "rays": j["rays"], "neural": j.get("neural")}
json.dump(rows, open(sys.argv[2], "w"), indent=1)
for k, r in rows.items():
    n = r["neural"] or {}
    print("%-34s %6.2f ms/spp  %.3g rays/s  %s" % (k, r["ms_per_spp"], r["rays_per_second"],
          "queries/ray %.2f, %.3g queries/s, leaf-cap rays %s" % (n["queries_per_ray"], n["queries_per_second"], n.get("leaf_cap_rays")) if n else ""))
    for p in ("traverse", "shadow", "neural_traverse", "neural_shadow"):
        if p in r["ns_per_ray_by_depth"]:
            print("    %-16s ns/ray by bounce: %s" % (p, " ".join("-" if x is None else "%.2f" % x for x in r["ns_per_ray_by_depth"][p])))
PY
