#!/usr/bin/env bash
# Prints how the resident memory of a long run grows: a leak per frame shows as a steady climb
# after the warm-up. Usage: scripts/memory_growth.sh [FRAMES, default 300] [RESOLUTION, default 128]
# Runs psv, metric_tree and ptsv on configs/smoke.json's scene (no reference, no plots) and samples
# VmRSS every second; the verdict compares the second half of the run with the first.
set -euo pipefail
cd "$(dirname "$0")/.."
frames="${1:-300}"
res="${2:-128}"
[ -x build/shadowlab ] || scripts/build.sh
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
build/shadowlab run configs/smoke.json --out "$out/run" --no-progress --set frames="$frames" \
  --set resolution="[$res,$res]" --set reference=false --set output.plots=false --set output.images_at_frames=[] \
  --set 'algorithms=[{"algorithm":"psv"},{"algorithm":"metric_tree"},{"algorithm":"ptsv"}]' --set expect=[] 2>"$out/log" &
pid=$!
start=$(date +%s)
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/VmRSS/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$rss" ] && echo "$(( $(date +%s) - start )) $rss" >>"$out/samples"
  sleep 1
done
wait "$pid" || { cat "$out/log"; exit 1; }
awk -v frames="$frames" -v res="$res" '
  { t[NR] = $1; r[NR] = $2 / 1024 }
  END {
    if (NR < 4) { print "too few samples: run more frames"; exit 1 }
    q = int(NR / 4); a = 0; b = 0
    for (i = q + 1; i <= 2 * q; i++) a += r[i]
    for (i = 3 * q + 1; i <= 4 * q; i++) b += r[i]
    a /= q; b /= q; max = 0
    for (i = 1; i <= NR; i++) if (r[i] > max) max = r[i]
    printf "%d frames at %d², %d samples over %d s: RSS second quarter %.1f MiB, last quarter %.1f MiB, peak %.1f MiB, growth %+.1f MiB\n",
           frames, res, NR, t[NR], a, b, max, b - a
  }' "$out/samples"
