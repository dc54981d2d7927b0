#!/usr/bin/env bash
# Fuzzes the scene parser (fuzz/scene_fuzz.cpp) with libFuzzer: clang with
# -fsanitize=fuzzer,address,undefined, the seed scenes of inputs/ as the corpus.
# Optional (needs clang: apt-get install clang); the normal build runs the same
# target with a standalone mutator (ctest -L fuzz).
#
#   scripts/fuzz.sh [SECONDS] [LIBFUZZER OPTIONS...]     default 600 s
#
# Findings (crash-*, leak-*, timeout-*, oom-* inputs) land in build-fuzz/; replay one
# with build-fuzz/scene_fuzz FILE.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang++ > /dev/null || { echo "scripts/fuzz.sh: needs clang++ (apt-get install clang)" >&2; exit 1; }
seconds=${1:-600}
shift || true
build=build-fuzz
mkdir -p "$build"
log="$build/build.log"
cmake -S fuzz -B "$build" -DCMAKE_CXX_COMPILER=clang++ > "$log" 2>&1 || { cat "$log"; exit 1; }
cmake --build "$build" -j "$(nproc)" >> "$log" 2>&1 || { tail -50 "$log"; exit 1; }
mkdir -p "$build/corpus"
cp inputs/*.xml inputs/*/*.xml "$build/corpus/"
"$build/scene_fuzz" -max_total_time="$seconds" -max_len=16384 -timeout=10 \
  -dict=fuzz/scene.dict -artifact_prefix="$build/" -print_final_stats=1 "$@" "$build/corpus"
