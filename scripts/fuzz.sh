#!/usr/bin/env bash
# Runs the libFuzzer targets of the config and glTF loaders for a while (needs clang, installed by
# scripts/setup.sh). Usage: scripts/fuzz.sh [config|gltf|both] [SECONDS per target, default 60]
# Seeds: the shipped configs, and the glTF files of Debian's assimp-testmodels. New interesting
# inputs go to build-fuzz/corpus-TARGET/; a crash is written as build-fuzz/crash-* and fails.
set -euo pipefail
cd "$(dirname "$0")/.."
which="${1:-both}"
seconds="${2:-60}"
scripts/setup.sh clang
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j"$(nproc)"
export ASAN_OPTIONS="detect_leaks=0"  # the loaders run millions of times; leak checks belong to test_sanitized.sh
run() {
  local target="$1" seeds="$2"
  mkdir -p "build-fuzz/corpus-$target"
  echo "fuzz: $target for $seconds s (seeds: $seeds)"
  # -rss_limit_mb: a case that allocates past this is a finding (the loaders check sizes first).
  build-fuzz/tests/fuzz/fuzz_$target -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=30 -max_len=2000000 \
    -artifact_prefix=build-fuzz/ "build-fuzz/corpus-$target" "$seeds"
}
if [ "$which" = config ] || [ "$which" = both ]; then
  seeds="build-fuzz/seeds-config"
  mkdir -p "$seeds"
  find configs tests/data -name '*.json' ! -name broken.json -exec cp {} "$seeds/" \;
  run config "$seeds"
fi
if [ "$which" = gltf ] || [ "$which" = both ]; then
  seeds="build-fuzz/seeds-gltf"
  mkdir -p "$seeds"
  find /usr/share/assimp/models/glTF2 \( -name '*.glb' -o -name '*.gltf' \) -size -2M -exec cp {} "$seeds/" \;
  run gltf "$seeds"
fi
