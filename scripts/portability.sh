#!/usr/bin/env bash
# The GPU-portability matrix (docs/portability.md): the GL tests that decide exactness, run on
# several OpenGL implementations of this machine, each cell checked to be what it claims first.
#
#   a  llvmpipe through OSMesa (build/tests/shadowlab_gl_tests, the normal test run's context)
#   b  zink (GL on Vulkan) over lavapipe through EGL, 128-bit vectors: 4-lane subgroups
#   c  zink over lavapipe, 256-bit vectors: 8-lane subgroups
#   d  llvmpipe through OSMesa without GL_ARB_shader_ballot (MESA_EXTENSION_OVERRIDE): the
#      algorithms' no-ballot paths
#
# In each cell: the cell check (PortabilityCellGLTest: renderer, back end, subgroup width, ballot
# against what the cell sets), then the conformance suite, the exact algorithms' accuracy tables, the
# forced-overflow tests (*TinyStack*, *TinyJobList*), the fault tests (*Fault*) and the portability
# table (PortabilityGLTest). A cell fails when its context is not what it claims, when it cannot
# make one, when a test fails or is skipped, or when it runs fewer tests than it lists (a crash).
# Writes results/portability/latest.md (the table) and latest.csv (its rows); exit 1 on any failure.
#
# Usage: scripts/portability.sh [--build DIR] [--out DIR] [--jobs N] [--zink-width BITS]
#                               [--a-from-ctest JUNIT.xml] [CELL...]
#   CELL: a b c d (default all). --zink-width adds a zink cell at that LP_NATIVE_VECTOR_WIDTH
#   (128 or 256; 512 is refused, see docs/portability.md). --jobs: cells run at once (default 2).
#   --a-from-ctest: cell a's suites other than the portability ones already ran in that ctest run
#   (the same binary and context: scripts/test.sh), so they are not run again; each of them must be
#   in its JUnit report, passed. The cell check and the portability table still run here.
# Nothing is installed or built here: scripts/test.sh runs it after building and testing.
set -euo pipefail
cd "$(dirname "$0")/.."

build=build
out=results/portability
jobs=2
a_junit=""
cells=()
extra_widths=()

refuse_width() {
    case "$1" in
    128 | 256) return 0 ;;
    512)
        cat >&2 <<'EOF'
portability: LP_NATIVE_VECTOR_WIDTH=512 is refused. Mesa 22.3's gallivm (the LLVM code generator
inside llvmpipe and lavapipe) cannot build rasterisation shaders for 512-bit vectors: the first draw
crashes in every Mesa path (OSMesa, llvmpipe through EGL, zink over lavapipe), with one-line shaders
too, while compute shaders run. Not ours, not zink's: docs/portability.md, "512-bit vectors".
EOF
        exit 2 ;;
    *) echo "portability: LP_NATIVE_VECTOR_WIDTH=$1: llvmpipe's widths are 128 and 256 here" >&2; exit 2 ;;
    esac
}

while [ $# -gt 0 ]; do
    case "$1" in
    --build) build="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --zink-width) refuse_width "$2"; extra_widths+=("$2"); shift 2 ;;
    --a-from-ctest) a_junit="$2"; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    a | b | c | d) cells+=("$1"); shift ;;
    *) echo "portability: unknown argument '$1' (see --help)" >&2; exit 2 ;;
    esac
done
[ ${#cells[@]} -gt 0 ] || [ ${#extra_widths[@]} -gt 0 ] || cells=(a b c d)
# A width inherited from the caller's environment would not reach the cells (each sets its own),
# but 512 there says someone expects it: refuse it by name rather than ignore it.
if [ -n "${LP_NATIVE_VECTOR_WIDTH:-}" ]; then refuse_width "$LP_NATIVE_VECTOR_WIDTH"; fi
for w in "${extra_widths[@]}"; do cells+=("zink$w"); done

osmesa_bin="$build/tests/shadowlab_gl_tests"
egl_bin="$build/tests/shadowlab_gl_tests_egl"
for b in "$osmesa_bin" "$egl_bin"; do
    [ -x "$b" ] || { echo "portability: $b is not built (scripts/build.sh builds it)" >&2; exit 1; }
done

# What every cell runs: SUITES, then the portability table. Cell d removes ARB_shader_ballot, which
# the packet rows of ptsv's accuracy table need: they are left out there (PortabilityGLTest asserts
# that ptsv refuses packets, its *_packet rows); nothing else is left out anywhere. The fault tests
# that need a ballot assert the refusal instead in that cell.
SUITES="Registry/ConformanceGLTest.*:ConformanceTimedPassGLTest.*:Registry/ChangeConformanceGLTest.*"
SUITES+=":Registry/SchemaConformanceTest.*"
SUITES+=":Table/PsvAccuracyGLTest.*:Table/PtsvAccuracyGLTest.*:Table/MetricTreeAccuracyGLTest.*"
SUITES+=":Table/BvhRaytraceAccuracyGLTest.*:Table/ShadowVolumesAccuracyGLTest.*:Table/IzbAccuracyGLTest.*:*TinyStack*:*TinyJobList*:*Fault*"
SUITES+=":ShadowVolumesGLTest.ParallelBorderIsFlaggedNotANaN:ExactFamilyGLTest.*"
TABLE="Table/PortabilityGLTest.*:PortabilityTableTest.*"
NO_BALLOT_EXCLUDED="Table/PtsvAccuracyGLTest.MatchesReference/*packet*"
if [ -n "$a_junit" ] && [ ! -s "$a_junit" ]; then
    echo "portability: --a-from-ctest $a_junit: no such report" >&2; exit 1
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/shadowlab-portability.XXXXXX")"
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

# cell_env NAME: the cell's description and environment, one KEY=VALUE per line after three header
# lines (label, binary, gtest negative filter). Each cell gets a private XDG_RUNTIME_DIR and a
# private, empty Mesa shader cache: Mesa 22.3's cache key leaves out LP_NATIVE_VECTOR_WIDTH, so a
# shared cache hands one width's binaries to another (docs/portability.md, "Shader cache").
cell_env() {
    local c="$1" dir="$work/$1"
    local common=("XDG_RUNTIME_DIR=$dir/xdg" "MESA_SHADER_CACHE_DIR=$dir/shader-cache" "SHADOWLAB_MATRIX_CELL=$c"
                  "SHADOWLAB_MATRIX_CSV=$dir/table.csv")
    case "$c" in
    a) printf '%s\n' "llvmpipe, OSMesa (the normal test run)" "$osmesa_bin" "" "${common[@]}" \
           SHADOWLAB_MATRIX_RENDERER=llvmpipe SHADOWLAB_MATRIX_BACKEND=OSMesa SHADOWLAB_MATRIX_BALLOT=1 ;;
    b) printf '%s\n' "zink over lavapipe, EGL, 128-bit vectors" "$egl_bin" "" "${common[@]}" \
           LIBGL_ALWAYS_SOFTWARE=1 MESA_LOADER_DRIVER_OVERRIDE=zink LP_NATIVE_VECTOR_WIDTH=128 \
           SHADOWLAB_MATRIX_RENDERER=zink SHADOWLAB_MATRIX_BACKEND=EGL SHADOWLAB_MATRIX_SUBGROUP=4 SHADOWLAB_MATRIX_BALLOT=1 ;;
    c) printf '%s\n' "zink over lavapipe, EGL, 256-bit vectors" "$egl_bin" "" "${common[@]}" \
           LIBGL_ALWAYS_SOFTWARE=1 MESA_LOADER_DRIVER_OVERRIDE=zink LP_NATIVE_VECTOR_WIDTH=256 \
           SHADOWLAB_MATRIX_RENDERER=zink SHADOWLAB_MATRIX_BACKEND=EGL SHADOWLAB_MATRIX_SUBGROUP=8 SHADOWLAB_MATRIX_BALLOT=1 ;;
    d) printf '%s\n' "llvmpipe, OSMesa, GL_ARB_shader_ballot removed" "$osmesa_bin" "$NO_BALLOT_EXCLUDED" "${common[@]}" \
           MESA_EXTENSION_OVERRIDE=-GL_ARB_shader_ballot \
           SHADOWLAB_MATRIX_RENDERER=llvmpipe SHADOWLAB_MATRIX_BACKEND=OSMesa SHADOWLAB_MATRIX_SUBGROUP=0 SHADOWLAB_MATRIX_BALLOT=0 ;;
    zink*) local w="${c#zink}"
           printf '%s\n' "zink over lavapipe, EGL, $w-bit vectors" "$egl_bin" "" "${common[@]}" \
           LIBGL_ALWAYS_SOFTWARE=1 MESA_LOADER_DRIVER_OVERRIDE=zink LP_NATIVE_VECTOR_WIDTH="$w" \
           SHADOWLAB_MATRIX_RENDERER=zink SHADOWLAB_MATRIX_BACKEND=EGL SHADOWLAB_MATRIX_SUBGROUP=$((w / 32)) SHADOWLAB_MATRIX_BALLOT=1 ;;
    esac
}

# Counts what a gtest JSON report says: "run passed failed skipped".
count_json() {
    /usr/bin/python3 - "$1" <<'EOF'
import json, sys
try:
    r = json.load(open(sys.argv[1], encoding="utf-8"))
except Exception:
    print("0 0 0 0"); sys.exit()
run = passed = failed = skipped = 0
for suite in r.get("testsuites", []):
    for t in suite.get("testsuite", []):
        if t.get("status") != "RUN": continue
        run += 1
        if t.get("failures"): failed += 1
        elif t.get("result") == "SKIPPED": skipped += 1
        else: passed += 1
print(run, passed, failed, skipped)
EOF
}

# Looks the tests of LIST (gtest's --gtest_list_tests output) up in ctest's JUnit report: prints
# "run passed failed skipped" (a test missing or not run counts as failed), their names to stderr.
count_junit() {
    /usr/bin/python3 - "$1" "$2" <<'EOF'
import sys, xml.etree.ElementTree as ET
names, suite = [], ""
for line in open(sys.argv[1], encoding="utf-8"):
    if line.startswith("  "): names.append(suite + line.split()[0])
    elif line.strip() and not line.startswith(" "): suite = line.split()[0]
# ctest names a parameterised case "NAME  # GetParam() = ...": the gtest name is what comes before.
status = {t.get("name").split("  # GetParam() = ")[0]: t.get("status") for t in ET.parse(sys.argv[2]).getroot().iter("testcase")}
run = passed = failed = skipped = 0
for n in names:
    st = status.get(n)
    if st is None or st == "notrun":
        failed += 1; print("not in the ctest run, or not run: " + n, file=sys.stderr); continue
    run += 1
    if st == "run": passed += 1
    elif st == "skipped": skipped += 1; print("skipped in the ctest run: " + n, file=sys.stderr)
    else: failed += 1; print("failed in the ctest run: " + n, file=sys.stderr)
print(run, passed, failed, skipped)
EOF
}

# run_cell NAME: runs one cell into $work/NAME; its verdict goes to $work/NAME/status.
run_cell() {
    local c="$1" dir="$work/$1"
    mkdir -p "$dir/xdg" "$dir/shader-cache"
    chmod 700 "$dir/xdg"
    local lines label bin exclude
    mapfile -t lines < <(cell_env "$c")
    label="${lines[0]}"; bin="${lines[1]}"; exclude="${lines[2]}"
    local envs=("${lines[@]:3}")
    # Nothing of the caller's choosing reaches a cell but what the cell sets itself.
    local clean=(env -u LP_NATIVE_VECTOR_WIDTH -u MESA_EXTENSION_OVERRIDE -u MESA_LOADER_DRIVER_OVERRIDE
                 -u LIBGL_ALWAYS_SOFTWARE -u GALLIUM_DRIVER -u MESA_SHADER_CACHE_DISABLE -u MESA_GL_VERSION_OVERRIDE
                 -u SHADOWLAB_MATRIX_SUBGROUP -u SHADOWLAB_MATRIX_BALLOT "${envs[@]}")
    local suites="$SUITES${exclude:+-$exclude}" filter="$SUITES:$TABLE${exclude:+-$exclude}" from_ctest=""
    if [ "$c" = a ] && [ -n "$a_junit" ]; then filter="$TABLE"; from_ctest=1; fi
    local start=$SECONDS verdict="ok" why=""
    echo "$label" >"$dir/label"
    printf '%s\n' "${envs[@]}" >"$dir/env"
    # 1. The cell is what it claims, or nothing else is run.
    "${clean[@]}" "$bin" --gtest_filter='PortabilityCellGLTest.*' --gtest_output="json:$dir/check.json" >"$dir/check.log" 2>&1 || true
    { grep -h '^\[portability-context\]' "$dir/check.log" || true; } | sed 1q >"$dir/context"
    local run passed failed skipped listed
    read -r run passed failed skipped < <(count_json "$dir/check.json")
    if [ "$run" -ne 1 ] || [ "$passed" -ne 1 ] || [ ! -s "$dir/context" ]; then
        verdict="failed"; why="the cell check failed (not the context it claims, or no context): see below"
    else
        # 2. The tests, counted against the list gtest gives for the same filter.
        listed=$("${clean[@]}" "$bin" --gtest_filter="$filter" --gtest_list_tests 2>/dev/null | grep -c '^  ' || true)
        local rc=0
        "${clean[@]}" "$bin" --gtest_filter="$filter" --gtest_output="json:$dir/tests.json" >"$dir/tests.log" 2>&1 || rc=$?
        if [ "$rc" -gt 128 ] && [ ! -s "$dir/tests.json" ]; then
            # Killed by a signal with no report written: a crash, so far only ever inside Mesa's zink
            # over lavapipe, once in many runs, and never under AddressSanitizer (docs/portability.md,
            # "Crashes"). The cell runs its tests once more and says so in the table; a second crash,
            # or any failure, fails the cell as always. The first run's log is kept (crash.log).
            local at
            at=$({ grep '^\[ RUN      \]' "$dir/tests.log" || true; } | tail -1 | sed 's/^\[ RUN      \] //')
            mv "$dir/tests.log" "$dir/crash.log"
            echo "the first run died of signal $((rc - 128)) in ${at:-its start}; its tests ran again" >"$dir/rerun"
            "${clean[@]}" "$bin" --gtest_filter="$filter" --gtest_output="json:$dir/tests.json" >"$dir/tests.log" 2>&1 || true
        fi
        read -r run passed failed skipped < <(count_json "$dir/tests.json")
        if [ -n "$from_ctest" ]; then
            # The suites' results come from the ctest run: every listed test looked up by name.
            "${clean[@]}" "$bin" --gtest_filter="$suites" --gtest_list_tests >"$dir/suites.list" 2>/dev/null || true
            local r2 p2 f2 s2
            read -r r2 p2 f2 s2 < <(count_junit "$dir/suites.list" "$a_junit" 2>"$dir/ctest-suites.log")
            listed=$((listed + $(grep -c '^  ' "$dir/suites.list" || true)))
            run=$((run + r2)); passed=$((passed + p2)); failed=$((failed + f2)); skipped=$((skipped + s2))
            echo "suites from the ctest run ($a_junit): $r2 ran, $p2 passed" >>"$dir/ctest-suites.log"
        fi
        echo "$listed $run $passed $failed $skipped" >"$dir/counts"
        if [ "$listed" -eq 0 ] || [ "$run" -eq 0 ]; then verdict="failed"; why="no test ran"
        elif [ "$failed" -ne 0 ]; then verdict="failed"; why="$failed tests failed or did not run"
        elif [ "$run" -ne "$listed" ]; then verdict="failed"; why="$run of $listed tests ran (the binary stopped: see the log)"
        elif [ "$skipped" -ne 0 ]; then verdict="failed"; why="$skipped tests skipped (a skip is a failure here)"
        elif [ "$passed" -ne "$listed" ]; then verdict="failed"; why="$passed of $listed tests passed"
        fi
    fi
    echo "$((SECONDS - start))" >"$dir/seconds"
    if [ -n "$from_ctest" ]; then echo "$a_junit" >"$dir/from-ctest"; fi
    if [ -f "$dir/rerun" ]; then why="${why:+$why; }$(cat "$dir/rerun")"; fi
    printf '%s\n%s\n' "$verdict" "$why" >"$dir/status"
    echo "portability: cell $c ($label): $verdict in $((SECONDS - start)) s${why:+: $why}"
}

# The zink cells take longest: they start first, so the two cores stay busy to the end.
order=()
for c in "${cells[@]}"; do [[ "$c" == a || "$c" == d ]] || order+=("$c"); done
for c in d a; do [[ " ${cells[*]} " == *" $c "* ]] && order+=("$c"); done
total_start=$SECONDS
running=0
for c in "${order[@]}"; do
    run_cell "$c" &
    running=$((running + 1))
    if [ "$running" -ge "$jobs" ]; then wait -n || true; running=$((running - 1)); fi
done
wait || true
total=$((SECONDS - total_start))

# The report, then the verdict.
/usr/bin/python3 scripts/portability_report.py "$work" "$out/latest.md" "$out/latest.csv" "$total" "${cells[@]}"
# Every cell's logs are kept beside the report ($out/logs/CELL-check.log, CELL-tests.log).
failed=0
rm -rf "$out/logs"
mkdir -p "$out/logs"
for c in "${cells[@]}"; do
    for log in "$work/$c"/*.log; do [ -f "$log" ] && cp "$log" "$out/logs/$c-$(basename "$log")"; done
    if [ "$(head -1 "$work/$c/status" 2>/dev/null)" != "ok" ]; then
        failed=1
        echo "portability: cell $c FAILED: $(sed -n 2p "$work/$c/status" 2>/dev/null)" >&2
        for log in check.log crash.log tests.log; do
            if [ -f "$work/$c/$log" ]; then
                echo "---- cell $c, $log: failures (all in $out/logs/$c-$log)" >&2
                { grep -E '^\[  FAILED  \]|^\[  SKIPPED \]|^\[portability-context\]' "$work/$c/$log" || true; } | sed 40q >&2
                tail -5 "$work/$c/$log" >&2
            fi
        done
    fi
done
echo "portability: ${#cells[@]} cells in $total s; table in $out/latest.md"
exit "$failed"
