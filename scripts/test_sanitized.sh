#!/usr/bin/env bash
# Builds shadowlab and its CPU tests with AddressSanitizer + UndefinedBehaviorSanitizer (CMake preset
# "asan", into build-asan/), runs the CPU tests and the smoke experiment under them. Any report fails.
# Suppressed: only leaks inside Mesa (scripts/sanitizers/lsan.supp says which and why).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake --preset asan >/dev/null
cmake --build --preset asan -j"$(nproc)"

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/sanitizers/lsan.supp:print_suppressions=0"

# The CPU tier (the GL tier's algorithms run inside Mesa, which is not instrumented). The GUI is not
# built here. Tests that run `shadowlab` run the sanitized binary. Left out: the EGL runner's tests
# (its run and its `info`),
# because Mesa's EGL driver is built without frame pointers, so LeakSanitizer's fast unwinder cannot
# see that its per-display allocations are Mesa's (with fast_unwind_on_malloc=0 they are, and are
# suppressed, but that run takes minutes); the smoke run below covers the same runner code on OSMesa.
# Also left out: SweepMemoryTest, which bounds a sweep's peak resident memory. AddressSanitizer keeps
# freed memory in its quarantine (256 MB by default), so resident size measures the sanitizer, not
# the sweep; the test runs in the plain tier (scripts/test.sh). And CliTest.EveryShippedConfigValidates:
# it checks the shipped configs (data, not code), and validating them builds every shipped scene up
# to 74 M triangles and line_space's trees for 2 M, past ctest's 10 minutes when instrumented; the
# same validate code runs here on every hostile input (HostileInputTest, UserTextTest, CliTest).
# And the exactness fuzzer's tests: they run the binary on hundreds of scenes, whose work is Mesa's
# (not instrumented); the smoke runs below take the same binary's paths under the sanitizers. For
# the same reason `info` (CliTest.InfoPrintsTheDeviceAndTheResolvedAutos compiles every algorithm's
# shaders in Mesa, many times slower instrumented: results/reference/ci_time_llvmpipe.md) and the
# example CI jobs (CiExamplesPython: runs on Mesa; their compare and history steps are
# HistoryTest's, which runs here) stay in the plain tier.
(cd build-asan && ctest --output-on-failure -j"$(nproc)" \
    -E "GLTest|GuiTest|gl_tests|EglRunner|EglInfo|SweepMemoryTest|EveryShippedConfigValidates|ExactnessFuzz|InfoPrintsTheDevice|CiExamplesPython" "$@")

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
build-asan/shadowlab run configs/smoke.json --out "$out/smoke" --no-progress
echo "sanitized smoke run: clean ($out/smoke)"
# Moving geometry: the GPU pose, the reference's and bvh_raytrace's refits, metric_tree's rigid clusters.
build-asan/shadowlab run configs/dynamic/cars_fence.json --set resolution=[48,48] --set frames=3 \
  --set output.images_at_frames=[2] --out "$out/dynamic" --no-progress
echo "sanitized moving-geometry run: clean ($out/dynamic)"
