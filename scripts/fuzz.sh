#!/usr/bin/env bash
# Fuzzes one of the two untrusted-input readers with libFuzzer (tests/fuzz/README.md):
#   scripts/fuzz.sh model|gltf [SECONDS=60] [more libFuzzer options...]
# Configures and builds build-fuzz/ (clang, -DNBVH_LIBFUZZER=ON, no CUDA), makes the corpus in
# build-fuzz/corpus-TARGET (model: seeds written by the current serialize_model; gltf: tests/fuzz/corpus/gltf
# and ../shared/scenes/bad are read as extra seed folders, never copied), runs the target for SECONDS and
# prints one summary line. Crash inputs land in build-fuzz/artifacts-TARGET/. Exit status: libFuzzer's.
# Build parallelism: NBVH_FUZZ_JOBS (default 2).
set -euo pipefail
cd "$(dirname "$0")/.."

target=${1:-}
seconds=${2:-60}
case "$target" in
model) max_len=1048576 ;; # 1 MiB: the seed models are ~40-110 KiB
gltf) max_len=262144 ;;   # 256 KiB
*)
    echo "usage: scripts/fuzz.sh model|gltf [SECONDS] [libFuzzer options...]" >&2
    exit 2
    ;;
esac
shift $(($# >= 2 ? 2 : $#))

build=build-fuzz
mkdir -p "$build"
cmake -S . -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DNBVH_LIBFUZZER=ON -DNBVH_CUDA=OFF >"$build/configure.log" 2>&1 || {
    cat "$build/configure.log" >&2
    exit 1
}
cmake --build "$build" -j"${NBVH_FUZZ_JOBS:-2}" --target "fuzz_$target" make_model_seeds

corpus=$build/corpus-$target
artifacts=$build/artifacts-$target
mkdir -p "$corpus" "$artifacts"
touch "$build/fuzz-start.stamp"
seeds=()
options=()
if [ "$target" = model ]; then
    "$build/tests/fuzz/make_model_seeds" "$corpus"
    [ -d tests/fuzz/corpus/model-regressions ] && seeds+=(tests/fuzz/corpus/model-regressions)
else
    seeds+=(tests/fuzz/corpus/gltf)
    options+=(-dict=tests/fuzz/gltf.dict)
    [ -d ../shared/scenes/bad ] && seeds+=(../shared/scenes/bad)
fi

log=$build/fuzz-$target.log
echo "fuzz.sh: $target for ${seconds} s, corpus $corpus (+ ${seeds[*]:-no seed folders}), log $log"
status=0
UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build/tests/fuzz/fuzz_$target" -max_total_time="$seconds" -rss_limit_mb=2048 -max_len="$max_len" -timeout=10 \
    -artifact_prefix="$artifacts/" -print_final_stats=1 "${options[@]}" "$@" "$corpus" "${seeds[@]}" >"$log" 2>&1 || status=$?

runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -1)
files=$(find "$corpus" -type f | wc -l)
bytes=$(du -sk "$corpus" | cut -f1)
crashes=$(find "$artifacts" -type f -newer "$build/fuzz-start.stamp" | wc -l)
if [ "$status" -ne 0 ]; then
    grep -E "^==[0-9]+==ERROR|^SUMMARY|runtime error|internal error|uncaught exception|Test unit written" "$log" | head -8 >&2 || true
fi
echo "fuzz.sh: $target: exit $status, ${runs:-?} executions in ${secs:-?} s, corpus $files files (${bytes} KiB), new artifacts: $crashes ($artifacts)"
exit "$status"
