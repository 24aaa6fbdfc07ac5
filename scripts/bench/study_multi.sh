#!/usr/bin/env bash
# One scene's study sweep spread over the GPUs of one host (issue 11): the nodes x hash grid is cut into
# parts, each part is a `scripts/bench/study.sh` run with `--device gpu:N` (its CUDA training follows to
# the same GPU), the GPUs run in parallel (a GPU with two parts runs them one after the other), and
# `merge_study.py` joins the parts into OUT/study.json. Every part renders the same references and noise
# floors (same seeds; the merge refuses parts whose floors differ), so the merged study is the one-GPU
# sweep's, in less time. With REFS=1 (default) the cameras' classical side (reference, floor, frame time,
# equal-time FLIPs up to EQUAL_TIME_UPTO x SPP, default 3) is rendered first, one camera per GPU in
# parallel (`nbvh study --references-only --reference-cameras C`), into OUT/references, and every part
# takes it from there (`--references`): the parts render no classical image, so a high-spp sweep fits.
# Usage (GPU machine, after `source .device/env.sh`): scripts/bench/study_multi.sh default|dragon|chess OUT
#   [extra nbvh study flags]
# Env: GPUS (default: the GPUs nvidia-smi lists), PARTS (default for the 3 x 3 sweep below: balanced for
#      any GPUS: at most 2 configurations a GPU from 5 GPUs on, the cheapest paired), BUDGET (minutes for the whole run, default 9.5: a part gets what is left when it
#      starts), plus study.sh's (SPP, REF_SPP, ...). PARTS is a list of NODES:HASH sub-grids, e.g.
#      "1000:14,16,18 2395:14,16 2395,8000:18 8000:14,16"; part i runs on GPU i % GPUS. PART_DEVICE
#      (default gpu:N) replaces every part's --device: a dry run on the build machine, e.g.
#      GPUS=2 PART_DEVICE=cpu BACKEND=cpu NBVH=build/app/nbvh PARTS="31:12 63:12" WIDTH=32 HEIGHT=32 SPP=2
#      REF_SPP=8 TIME_WIDTH=32 TIME_HEIGHT=32 LODS=1 CAMERAS=1 scripts/bench/study_multi.sh default OUT
#      --steps 20 --batch 256 --threads 1. CAP_AT (default 2395:16): the configuration of the cap rows.
# The raised-leaf-budget row (--cap-study) runs once, in the part that holds nodes 2395 x hash 2^16 as its
# middle configuration (as in the one-GPU sweep); the camera-0 PNGs come from the part that ends with
# the grid's last configuration.
set -euo pipefail
cd "$(dirname "$0")/../.."
WHICH=$1 OUT=$2
shift 2
GPUS=${GPUS:-$(nvidia-smi -L 2>/dev/null | grep -c '^GPU' || true)}
[ "${GPUS:-0}" -ge 1 ] || { echo "study_multi.sh: no GPU found (set GPUS)" >&2; exit 2; }
if [ -z "${PARTS:-}" ]; then
  case "$GPUS" in
    1) PARTS="1000,2395,8000:14,16,18" ;;
    2) PARTS="2395:14,16,18 1000:14,16,18 8000:18 8000:14,16" ;;
    3) PARTS="1000:14,16,18 2395:14,16,18 8000:14,16,18" ;;
    4) PARTS="1000:14,16,18 2395:14,16 2395,8000:18 8000:14,16" ;;
    5) PARTS="1000:14,16 1000,2395:18 2395:14,16 8000:14,16 8000:18" ;;
    6) PARTS="1000:14,16 1000,2395:18 2395:14 2395:16 8000:14,16 8000:18" ;;
    7) PARTS="1000:14,16 1000,2395:18 2395:14 2395:16 8000:14 8000:16 8000:18" ;;
    8) PARTS="1000:14,16 1000:18 2395:14 2395:16 2395:18 8000:14 8000:16 8000:18" ;;
    *) PARTS="1000:14 1000:16 1000:18 2395:14 2395:16 2395:18 8000:14 8000:16 8000:18" ;;
  esac
fi
mkdir -p "$OUT"
# Unpack a carried scene once, before the parts start (study.sh unpacks into the same folder).
TMP=${TMPDIR:-/tmp}/nbvh_study
mkdir -p "$TMP"
source scripts/bench/lib.sh
case "$WHICH" in
  dragon) unpack .device/study/dragon/dragon_vrip.glb.xz "$TMP/dragon_vrip.glb" ;;
  chess) unpack .device/study/chess/abeautifulgame.glb.xz "$TMP/abeautifulgame.glb" ;;
esac
export NBVH_STUDY_UNPACKED=1 # study.sh: the scene is in $TMP already (parts must not rewrite it)

cap_for() { # NODES HASH: 64 when the part's middle configuration is CAP_AT (default 2395:16, the one-GPU
  # sweep's middle configuration), else 0
  local -a n h c=()
  IFS=, read -r -a n <<< "$1"
  IFS=, read -r -a h <<< "$2"
  for a in "${n[@]}"; do for b in "${h[@]}"; do c+=("$a:$b"); done; done
  if [ "${c[$(( ${#c[@]} / 2 ))]}" = "${CAP_AT:-2395:16}" ]; then echo 64; else echo 0; fi
}
total_s=$(python3 -c "import sys; print(int(float(sys.argv[1]) * 60))" "${BUDGET:-9.5}")
t_start=$(date +%s)
REFARGS=()
if [ "${REFS:-1}" = 1 ]; then
  REFARGS=(--references "$OUT/references")
  pids=()
  for c in $(seq 0 $(( ${CAMERAS:-3} - 1 ))); do
    g=$(( c % GPUS ))
    dev=${PART_DEVICE:-gpu:$g}
    echo "camera $c: classical side on $dev"
    DEVICE=$dev scripts/bench/study.sh "$WHICH" "$OUT/references_cam$c" "${REFARGS[@]}" --references-only \
      --reference-cameras "$c" --equal-time-upto "${EQUAL_TIME_UPTO:-3}" "$@" > "$OUT/references_cam$c.out" 2>&1 &
    pids+=($!)
    if [ $(( (c + 1) % GPUS )) = 0 ]; then for p in "${pids[@]}"; do wait "$p" || status_refs=1; done; pids=(); fi
  done
  for p in "${pids[@]}"; do wait "$p" || status_refs=1; done
  [ "${status_refs:-0}" = 0 ] || { echo "study_multi.sh: a camera's classical side failed: $OUT/references_cam*.out" >&2; exit 1; }
  echo "classical sides of ${CAMERAS:-3} camera(s) in $(( $(date +%s) - t_start )) s"
fi
read -r -a LIST <<< "$PARTS"
declare -a QUEUE # per GPU: the part indices it runs, in order
for i in "${!LIST[@]}"; do QUEUE[$((i % GPUS))]+="$i "; done
t0=$t_start # the budget counts the classical sides too
pids=()
for g in $(seq 0 $((GPUS - 1))); do
  (
    for i in ${QUEUE[$g]:-}; do
      part=${LIST[$i]}
      nodes=${part%%:*} hash=${part##*:}
      cap=$(cap_for "$nodes" "$hash")
      left=$(python3 -c "import sys; print(round(max(0.0, float(sys.argv[1])) / 60, 2))" \
             "$(( total_s - ($(date +%s) - t0) ))")
      dev=${PART_DEVICE:-gpu:$g}
      echo "part $i ($nodes x $hash) on $dev, cap-study $cap, budget $left min"
      DEVICE=$dev NODES=$nodes HASH=$hash BUDGET=$left scripts/bench/study.sh "$WHICH" "$OUT/part_$i" \
        --cap-study "$cap" "${REFARGS[@]}" "$@" > "$OUT/part_$i.out" 2>&1 || { echo "part $i failed: $OUT/part_$i.out" >&2; exit 1; }
    done
  ) &
  pids+=($!)
done
status=0
for p in "${pids[@]}"; do wait "$p" || status=1; done
echo "all parts ended after $(( $(date +%s) - t0 )) s (status $status)"
PARTFILES=()
for i in "${!LIST[@]}"; do
  [ -f "$OUT/part_$i/study.json" ] && PARTFILES+=("$OUT/part_$i/study.json")
done
[ ${#PARTFILES[@]} -gt 0 ] || { echo "study_multi.sh: no part wrote study.json" >&2; exit 1; }
python3 scripts/bench/merge_study.py "$OUT/study.json" "${PARTFILES[@]}"
# Camera 0's images: the part whose grid holds nodes 8000 x 2^18, the one-GPU sweep's last configuration.
for i in "${!LIST[@]}"; do
  part=${LIST[$i]}
  case ",${part%%:*}," in *,8000,*) ;; *) continue ;; esac
  case ",${part##*:}," in *,18,*) cp "$OUT/part_$i"/*_cam0.png "$OUT"/ 2>/dev/null || true ;; esac
done
cat "$OUT"/references_cam*/log.txt "$OUT"/part_*/log.txt > "$OUT/log.txt" 2>/dev/null || true
echo "wrote $OUT/study.json (${#PARTFILES[@]} parts on $GPUS GPU(s)) in $(( $(date +%s) - t0 )) s"
exit $status
