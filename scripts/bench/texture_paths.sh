#!/usr/bin/env bash
# Both texture paths (engine/render/texture_path.h) on a GPU with descriptor indexing, in one run:
#   1. nbvh_render_gpu_tests (buffer vs array on a generated textured scene, with the validation layer
#      when DIR/layer has it);
#   2. Chess (../shared/scenes/abeautifulgame, its 33 2048^2 textures) classical at 1920x1080 through the
#      texel buffer and through the image array, same seed: GPU time per sample, texture memory, LDR-FLIP
#      between the two beside the noise floor (the buffer path with another seed); a warm-up render first;
#   3. the array path on Chess once more under the validation layer (small image): its message count.
# Camera and environment as scripts/bench/chess.sh. Writes OUT/summary.txt, OUT/texture_paths.json,
# OUT/gpu_test.txt, OUT/{buffer,array}_stats.json, OUT/array.png, OUT/flip_buffer_array.png.
# Usage (GPU machine):  source .device/env.sh && scripts/bench/texture_paths.sh DIR $OUT
#   DIR: bin/nbvh[.xz], bin/nbvh_render_gpu_tests[.xz], scene/abeautifulgame.glb[.xz],
#        scene/photo_studio_loft_hall_512x256.hdr, optionally layer/ (VkLayer_khronos_validation.json and
#        libVkLayer_khronos_validation.so[.xz] from Debian's vulkan-validationlayers). env: SPP (default 32), WIDTH, HEIGHT
#        (default 1920x1080).
set -uo pipefail
DIR=$1 OUT=$2
SPP=${SPP:-32} W=${WIDTH:-1920} H=${HEIGHT:-1080}
T=${TMPDIR:-/tmp}/texture_paths
mkdir -p "$T" "$OUT"
unpack() { # FILE[.xz] -> $T/basename, executable
  local src=$1 dst="$T/$(basename "${1%.xz}")"
  if [[ $src == *.xz ]]; then
    if command -v xz >/dev/null; then xz -dc "$src" > "$dst"
    else python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' "$src" "$dst"; fi
  else cp "$src" "$dst"; fi
  chmod +x "$dst"
}
for f in "$DIR"/bin/*; do unpack "$f"; done
NBVH=$T/nbvh
if [ -d "$DIR/layer" ]; then
  mkdir -p "$T/layer"
  cp "$DIR"/layer/*.json "$T/layer/"
  for f in "$DIR"/layer/*.so*; do unpack "$f"; mv "$T/$(basename "${f%.xz}")" "$T/layer/"; done
  export VK_LAYER_PATH=$T/layer
  # The manifest names the library without a path: the loader finds it through the dynamic linker.
  export LD_LIBRARY_PATH="$T/layer${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
S=$OUT/summary.txt
(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || echo "no nvidia-smi") > "$S"
echo "spp $SPP, ${W}x$H, max depth 8, classical" >> "$S"

"$T/nbvh_render_gpu_tests" > "$OUT/gpu_test.txt" 2>&1
echo "gpu test exit $?: $(grep -E '^\[  (PASSED|FAILED|SKIPPED) ' "$OUT/gpu_test.txt" | tr '\n' ' ')" >> "$S"
grep -E "^(direct|path traced)" "$OUT/gpu_test.txt" >> "$S"

SCENE=$DIR/scene/abeautifulgame.glb ENV=$DIR/scene/photo_studio_loft_hall_512x256.hdr
if [ ! -f "$SCENE" ] && [ -f "$SCENE.xz" ]; then unpack "$SCENE.xz"; SCENE=$T/abeautifulgame.glb; fi
R=("$NBVH" render "$SCENE" --camera "0.600,0.358,0.179,-0.197,-0.197,-0.057,45" --env "$ENV" --env-rotation 285
   --width "$W" --height "$H" --max-depth 8 --exposure 0)
for p in buffer array; do "${R[@]}" --texture-path $p --explain 2>&1 | grep -A1 "^  textures" >> "$S"; done
"${R[@]}" --spp 4 --out "$T/warmup.png" > /dev/null 2>&1 # clocks, caches
render() { # PATH SEED OUTPNG STATS
  local t0 t1
  t0=$(date +%s.%N)
  "${R[@]}" --texture-path "$1" --seed "$2" --spp "$SPP" --out "$3" --stats "$4" 2>&1 | grep -E "GPU,|textures:" >> "$S"
  t1=$(date +%s.%N)
  echo "$1 seed $2: process wall $(python3 -c "print(round($t1 - $t0, 2))") s" >> "$S"
}
render buffer 1 "$T/buffer.png" "$OUT/buffer_stats.json"
render array 1 "$OUT/array.png" "$OUT/array_stats.json"
render buffer 2 "$T/buffer_seed2.png" "$T/buffer_seed2_stats.json"
FLIP_PATHS=$("$NBVH" flip "$T/buffer.png" "$OUT/array.png" --heatmap "$OUT/flip_buffer_array.png" 2>&1 | tail -1)
FLIP_FLOOR=$("$NBVH" flip "$T/buffer.png" "$T/buffer_seed2.png" 2>&1 | tail -1)
echo "LDR-FLIP buffer vs array (seed 1): $FLIP_PATHS" >> "$S"
echo "noise floor, buffer seed 1 vs seed 2: $FLIP_FLOOR" >> "$S"

VAL=unavailable
if [ -n "${VK_LAYER_PATH:-}" ]; then
  NBVH_VALIDATION=1 "$NBVH" render "$SCENE" --texture-path array --width 480 --height 270 --spp 2 --max-depth 4 \
    --out "$T/validation.png" > "$T/validation.txt" 2>&1
  RC=$?
  VAL=$(grep -c "vulkan validation" "$T/validation.txt")
  grep -q "not installed" "$T/validation.txt" && VAL=unavailable
  # A render that did not finish counted nothing: say so instead of reporting 0 messages.
  [ "$RC" -eq 0 ] || VAL="render failed (exit $RC): $(tail -1 "$T/validation.txt")"
fi
echo "validation messages, array path on Chess (480x270, 2 spp): $VAL" >> "$S"

python3 - "$OUT" "$T" "$SPP" "$FLIP_PATHS" "$FLIP_FLOOR" "$VAL" <<'EOF'
import json, re, subprocess, sys
out, t, spp, flip_paths, flip_floor, val = sys.argv[1:]
def num(text):
    m = re.search(r"[-+]?\d*\.\d+(?:[eE][-+]?\d+)?|\d+", text)
    return float(m.group()) if m else None
def stats(path):
    global b_w, b_h
    s = json.load(open(path))
    b_w, b_h = s["width"], s["height"]
    return {"texture_path": s["textures"]["path"], "textures": s["textures"]["count"],
            "texture_gpu_bytes": s["textures"]["gpu_bytes"], "texture_halvings": s["textures"]["halvings"],
            "gpu_ms": s["gpu_total_ms"], "gpu_ms_per_spp": s["gpu_total_ms"] / s["spp"], "wall_ms": s["wall_ms"],
            "pass_gpu_ms": s["pass_gpu_ms"], "rays_per_second": s["rays_per_second"]}
gpu = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version", "--format=csv,noheader"],
                     capture_output=True, text=True).stdout.strip()
b, a = stats(f"{out}/buffer_stats.json"), stats(f"{out}/array_stats.json")
j = {"device": gpu, "scene": "abeautifulgame.glb (Chess), classical, max depth 8, camera/env of scripts/bench/chess.sh",
     "width": b_w, "height": b_h,
     "spp": int(spp), "buffer": b, "array": a,
     "array_over_buffer_gpu_time": a["gpu_ms"] / b["gpu_ms"],
     "flip_ldr_buffer_vs_array_same_seed": num(flip_paths), "flip_ldr_noise_floor_buffer_seeds_1_2": num(flip_floor),
     "validation_messages_array_path": val}
json.dump(j, open(f"{out}/texture_paths.json", "w"), indent=2)
print(json.dumps({k: v for k, v in j.items() if k not in ("buffer", "array")}, indent=1))
EOF
cat "$S"
