#!/usr/bin/env bash
# Build-machine half of the study runs (issue 11; ../shared/device/README.md): puts what a GPU run of
# scripts/bench/study.sh needs into ignored folders, each carried only by the runs that need it:
#   .device/study/bin/nbvh      the stripped binary (its shared libraries go to .device/lib via prepare.sh)
#   .device/study/dragon/       dragon_vrip.glb.xz (15 MB -> 5 MB: the checkout and carry travel in 64 MiB)
#   .device/study/chess/        abeautifulgame.glb.xz (28 MB -> 20 MB) and the Chess environment map
# Usage (project root): scripts/bench/study_prepare.sh [BUILD_DIR]   (default build-h11; build it first with
#   cmake -S . -B BUILD_DIR -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CUDA_ARCHITECTURES=90
#   && cmake --build BUILD_DIR --target nbvh)
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD=${1:-build-h11}
SCENES=${NBVH_SCENES:-../shared/scenes}
[ -x "$BUILD/app/nbvh" ] || { echo "study_prepare: $BUILD/app/nbvh not built" >&2; exit 1; }
mkdir -p .device/study/bin .device/study/dragon .device/study/chess
strip -o .device/study/bin/nbvh "$BUILD/app/nbvh"
../shared/device/prepare.sh .device/study/bin/nbvh >/dev/null
pack() { # SRC DST: xz, once per version of SRC
  if [ ! "$2" -nt "$1" ]; then xz -T2 -6 -c "$1" > "$2.tmp" && mv -f "$2.tmp" "$2"; fi
}
pack "$SCENES/stanford_dragon/dragon_vrip.glb" .device/study/dragon/dragon_vrip.glb.xz
pack "$SCENES/abeautifulgame/abeautifulgame.glb" .device/study/chess/abeautifulgame.glb.xz
cp -u "$SCENES/hdris/photo_studio_loft_hall_512x256.hdr" .device/study/chess/
du -sh .gl .device/lib .device/study/bin .device/study/dragon .device/study/chess
echo "working tree (tracked + untracked, not ignored): $(git ls-files -co --exclude-standard -z | du -ch --files0-from=- 2>/dev/null | tail -1 | cut -f1)"
