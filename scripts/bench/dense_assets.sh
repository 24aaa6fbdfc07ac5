#!/usr/bin/env bash
# Where the network pays off in time (issue 14, "dense assets"): the same surface in 4^L times the
# triangles (`--subdivide L`, flat midpoint subdivision of every mesh, engine/scene/subdivide.h), so only
# the classical side's cost changes, as between a modest mesh and a dense scan of the same shape (the
# paper's Statuette). One binary, one GPU call. Per scene and level:
#   - a model trained by `nbvh train --subdivide L` with no other flag (its wall time recorded);
#   - 1920x1080, SPP (16) spp, max depth 8, render defaults: classical, hybrid, classical, hybrid (REPS
#     rounds, the fastest of each; GPU timestamps), each after WARMUP (16, the most nbvh render takes)
#     untimed renders of the same image in its process (~0.3-0.6 s of GPU work: the GPU idles through a
#     large scene's BVH build and starts the next frame at low clocks; separate warm-up processes do not
#     help there, and two warm-up renders left both classical renders of the dragon at level 1 3-4x slow);
#   - then one more render per side without warm-up: its wall time (load, subdivision, BVH builds,
#     pipelines, the frame, the PNG: what a user waits for one image) and its "BVHs built in" time;
#   - at FLIP_W x FLIP_H (960x540), FLIP_SPP (2048) spp: a classical reference of seed 7, the classical
#     render of seed 0 (the noise floor) and the hybrid of seed 0, LDR-FLIP of both against the reference.
# Usage (GPU machine, after `source .device/env.sh`): SCENES="dragon default" LEVELS="0 1 2" \
#   scripts/bench/dense_assets.sh OUT     (NBVH: the binary, default .device/study/bin/nbvh)
# Env also: WIDTH, HEIGHT (1920x1080), REPS (timed renders per side, 2), WARMUP (16), TRAIN_ARGS (extra
# `nbvh train` flags; CI's dry run trains tiny CPU models with them, tests/bench/bench_scripts_dry_run.sh).
# Writes OUT/dense.json (every row), OUT/train_SCENE_L.log, OUT/device.txt; prints a table.
set -euo pipefail
cd "$(dirname "$0")/../.."
source scripts/bench/lib.sh
OUT=$1
bench_setup "$OUT" dense
rm -f "$T"/*.train.json # rows of an earlier call on a warm machine
R=(--width "${WIDTH:-1920}" --height "${HEIGHT:-1080}" --max-depth 8 --exposure 0 --spp "${SPP:-16}")
F=(--width "${FLIP_W:-960}" --height "${FLIP_H:-540}" --max-depth 8 --exposure 0 --spp "${FLIP_SPP:-2048}")
summarize() { # OUT/dense.json from every level done so far (a call cut short keeps its finished rows)
python3 - "$T" "$OUT/dense.json" "$B" <<'PY'
import glob, json, os, re, sys
t, out = sys.argv[1], sys.argv[2]
num = lambda f: float(re.search(r"[-+]?\d*\.\d+(?:[eE][-+]?\d+)?|\d+", open(f).read()).group())
rows = []
for train in sorted(glob.glob(os.path.join(t, "*.train.json"))):
    p = train[: -len(".train.json")]
    scene, level = os.path.basename(p).rsplit("_", 1)
    side = {}
    for s in ("classical", "hybrid"):
        runs = [json.load(open(f)) for f in sorted(glob.glob(f"{p}.{s}_[0-9]*.json"))]
        best = min(runs, key=lambda j: j["gpu_total_ms"])
        spp = best["spp"]
        bvh = re.search(r"BVHs built in ([0-9.]+) ms", open(f"{p}.{s}_wall.log").read())
        side[s] = {"ms_per_spp": best["gpu_total_ms"] / spp, "all_ms_per_spp": [j["gpu_total_ms"] / spp for j in runs],
                   "rays_per_second": best["rays_per_second"], "neural": best.get("neural"),
                   "passes_ms_per_spp": {k.split("/")[-1].replace(".comp", ""): v / spp for k, v in best["pass_gpu_ms"].items()},
                   "device": best["device"], "driver": best["driver"], "commit": best["commit"],
                   "wall_s": num(f"{p}.{s}_wall.wall"), "bvh_build_ms": float(bvh.group(1)) if bvh else None}
    log = open(os.path.join(os.path.dirname(out), f"train_{scene}_{level}.log")).read()
    tri = re.search(r"training .*?\((\d+) triangles\)", log)
    rows.append({"scene": scene, "subdivide": int(level), "asset_triangles": int(tri.group(1)) if tri else None,
                 "train_wall_s": json.load(open(train))["train_wall_s"],
                 "classical": side["classical"], "hybrid": side["hybrid"],
                 "hybrid_over_classical": side["hybrid"]["ms_per_spp"] / side["classical"]["ms_per_spp"],
                 "hybrid_over_classical_wall": side["hybrid"]["wall_s"] / side["classical"]["wall_s"],
                 "flip_hybrid_vs_ref": num(p + ".flip_hybrid.txt"), "flip_floor": num(p + ".flip_floor.txt")})
json.dump({"binary": sys.argv[3], "rows": rows}, open(out, "w"), indent=1)
print("%-8s %2s %11s %12s %12s %7s %9s %8s %8s %17s" % ("scene", "L", "triangles", "classical", "hybrid", "ratio",
                                                       "train s", "FLIP", "floor", "render wall c/h s"))
for r in rows:
    print("%-8s %2d %11s %9.3f ms %9.3f ms %6.2fx %9.1f %8.4f %8.4f %8.1f / %6.1f" % (
        r["scene"], r["subdivide"], r["asset_triangles"], r["classical"]["ms_per_spp"], r["hybrid"]["ms_per_spp"],
        r["hybrid_over_classical"], r["train_wall_s"], r["flip_hybrid_vs_ref"], r["flip_floor"],
        r["classical"]["wall_s"], r["hybrid"]["wall_s"]))
PY
}
timed() { # SIDE REP WARMUP ARGS...: one render of level P, its stats, log and wall seconds
  local f=$P.$1_$2 w=$3 s
  shift 3
  s=$(date +%s.%N)
  "$B" render "$@" "${R[@]}" --warmup "$w" --stats "$f.json" > "$f.log" 2>&1 || { tail -3 "$f.log"; exit 1; }
  python3 -c "import sys; print(float(sys.argv[2]) - float(sys.argv[1]))" "$s" "$(date +%s.%N)" > "$f.wall"
}
# shellcheck disable=SC2206
TA=(${TRAIN_ARGS:-})
for scene in ${SCENES:-dragon default}; do
  bench_scene "$scene" "$T"
  for L in ${LEVELS:-0 1 2}; do
    P=$T/${scene}_$L
    D=(--subdivide "$L")
    t0=$(date +%s.%N)
    "$B" train "${SRC[@]}" "${NEURAL[@]}" "${D[@]}" "${TA[@]}" --out "$P.nbvh" > "$OUT/train_${scene}_$L.log" 2>&1
    t1=$(date +%s.%N)
    echo "{\"train_wall_s\": $(python3 -c "print($t1 - $t0)")}" > "$P.train.json"
    C=("${SRC[@]}" "${NEURAL[@]}" --classical "${VIEW[@]}" "${D[@]}")
    H=("${SRC[@]}" --model "$P.nbvh" "${VIEW[@]}" "${D[@]}")
    for rep in $(seq "${REPS:-2}"); do
      timed classical "$rep" "${WARMUP:-16}" "${C[@]}" --out "$T/c.png"
      timed hybrid "$rep" "${WARMUP:-16}" "${H[@]}" --out "$T/h.png"
    done
    timed classical wall 0 "${C[@]}" --out "$T/c.png"
    timed hybrid wall 0 "${H[@]}" --out "$T/h.png"
    "$B" render "${C[@]}" "${F[@]}" --seed 7 --out "$P.ref.png" > /dev/null 2>&1
    "$B" render "${C[@]}" "${F[@]}" --out "$P.cl.png" > /dev/null 2>&1
    "$B" render "${H[@]}" "${F[@]}" --out "$P.hy.png" > /dev/null 2>&1
    "$B" flip "$P.ref.png" "$P.cl.png" | tail -1 > "$P.flip_floor.txt"
    "$B" flip "$P.ref.png" "$P.hy.png" | tail -1 > "$P.flip_hybrid.txt"
    echo "done $scene L=$L ($(date +%T))"
    summarize > "$OUT/table.txt"
  done
done
cat "$OUT/table.txt"
