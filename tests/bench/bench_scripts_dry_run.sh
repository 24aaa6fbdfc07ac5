#!/usr/bin/env bash
# The GPU machine's A/B scripts run end to end here (lavapipe, CPU training, tiny images): variant_flips.sh
# over flag_sweep.sh and lib.sh on the default scene with two variants must write a sweep.json whose
# rows have finite, positive frame times and a flips.txt with the floor and both variants' FLIPs; an
# unknown scene must fail with a one-line error. Usage: bench_scripts_dry_run.sh NBVH WORKDIR
set -euo pipefail
NBVH=$(realpath "$1") W=$2
rm -rf "$W" && mkdir -p "$W"
cd "$(dirname "$0")/../.."
export NBVH TMPDIR=$W TRAIN_ARGS="--backend cpu --steps 20 --batch 256 --nodes 31 --hash-log2 10" WIDTH=32 HEIGHT=18 \
  SPP=1 REPS=1 WARMUP=1 FLIP_W=32 FLIP_H=18 FLIP_SPP=2 SCENES=default VARIANTS=$'fit|--neural-materials fit\nmix|'
scripts/bench/variant_flips.sh "$W/out" > "$W/log" 2>&1 || { cat "$W/log"; exit 1; }
python3 - "$W/out" <<'PY'
import json, math, re, sys
out = sys.argv[1]
rows = json.load(open(out + "/sweep/sweep.json"))["rows"]
assert sorted(rows) == ["default_classical", "default_fit", "default_mix"], sorted(rows)
for k, r in rows.items():
    assert math.isfinite(r["ms_per_spp"]) and r["ms_per_spp"] > 0, (k, r["ms_per_spp"])
line = open(out + "/flips.txt").read()
nums = re.findall(r"Mean: ([0-9.]+)", line)
assert line.startswith("default floor(classical vs ref)") and len(nums) == 5, line  # floor + 2 x 2 FLIPs
assert all(math.isfinite(float(x)) and 0 <= float(x) < 1 for x in nums), nums
print("variant_flips.sh dry run:", line.strip())
PY
if SCENES=nowhere scripts/bench/variant_flips.sh "$W/bad" > "$W/bad.log" 2>&1; then
  echo "an unknown scene was accepted"; exit 1
fi
grep -q "bench_scene: scene must be default, dragon or chess, not 'nowhere'" "$W/bad.log" || { cat "$W/bad.log"; exit 1; }
# dense_assets.sh: two --subdivide levels of the default scene, the asset's triangles 4x apart.
SCENES=default LEVELS="0 1" FLIP_SPP=2 scripts/bench/dense_assets.sh "$W/dense" > "$W/dense.log" 2>&1 \
  || { cat "$W/dense.log"; exit 1; }
python3 - "$W/dense/dense.json" <<'PY'
import json, math, sys
rows = json.load(open(sys.argv[1]))["rows"]
assert [(r["scene"], r["subdivide"]) for r in rows] == [("default", 0), ("default", 1)], rows
assert rows[1]["asset_triangles"] == 4 * rows[0]["asset_triangles"], [r["asset_triangles"] for r in rows]
for r in rows:
    for k in ("hybrid_over_classical", "flip_hybrid_vs_ref", "flip_floor"):
        assert math.isfinite(r[k]) and r[k] >= 0, (k, r[k])
    assert r["classical"]["ms_per_spp"] > 0 and r["hybrid"]["neural"]["queries"] > 0, r
    for side in ("classical", "hybrid"):  # wall times of the renders, their BVH build times from the logs
        assert r[side]["wall_s"] > 0 and r[side]["bvh_build_ms"] >= 0, r[side]
print("dense_assets.sh dry run:", [(r["subdivide"], r["asset_triangles"], round(r["hybrid_over_classical"], 2)) for r in rows])
PY
grep -q "BVHs built in .* (the neural-only meshes' bounds only" "$W/nbvh_dense/default_1.hybrid_wall.log" \
  || { echo "the hybrid render built the neural asset's BLAS"; cat "$W/nbvh_dense/default_1.hybrid_wall.log"; exit 1; }
echo "ok"
