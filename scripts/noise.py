#!/usr/bin/env python3
"""How noisy this machine's timings are, and whether `shadowlab compare` calls two runs of the same
build the same: runs CONFIG 2 x TRIALS times with `repeats` R, compares run 2k with run 2k+1, and
prints per algorithm id the width of the 95 % interval of its total time (as a share of the median)
and how many of the TRIALS comparisons called it slower or faster (same build: should be none).

Usage: scripts/noise.py CONFIG REPEATS TRIALS OUT_DIR [--relative-to ID] [--set PATH=VALUE ...]
(argv only: every path and value goes to shadowlab as one argument, never through a shell)
"""
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BINARY = os.path.join(HERE, "..", "build", "shadowlab")


def run(config, repeats, out, extra):
    args = [BINARY, "run", config, "--out", out, "--force", "--no-progress", "--set", f"repeats={repeats}",
            "--set", "output.plots=false", "--set", "output.images_at_frames=[]"] + extra
    done = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode not in (0, 3):
        sys.exit(f"noise: {' '.join(args)} failed: {done.stderr.strip().splitlines()[-1:]}")
    with open(os.path.join(out, "summary.json"), encoding="utf-8") as f:
        return json.load(f)


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    config, repeats, trials, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    extra = sys.argv[5:]
    relative = []
    if extra[:1] == ["--relative-to"]:
        relative, extra = extra[:2], extra[2:]
    os.makedirs(out, exist_ok=True)
    widths, calls, wall = {}, {}, []
    for t in range(trials):
        pair = []
        for side in ("a", "b"):
            folder = os.path.join(out, f"t{t}{side}")
            summary = run(config, repeats, folder, extra)
            wall.append(summary["wall_time_s"])
            pair.append(folder)
            for alg, entry in summary["algorithms"].items():
                ci = entry.get("time_ms_interval", {}).get("total")
                if ci and ci["median"] > 0:
                    widths.setdefault(alg, []).append((ci["high"] - ci["low"]) / ci["median"])
        cmp_dir = os.path.join(out, f"t{t}-compare")
        subprocess.run([BINARY, "compare", pair[0], pair[1], "--out", cmp_dir, "--force"] + relative,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with open(os.path.join(cmp_dir, "compare.json"), encoding="utf-8") as f:
            for rec in json.load(f)["ids"]:
                total = [s for s in rec.get("time", []) if s["stage"] == "total"]
                verdict = total[0]["verdict"] if total else "absent"
                if verdict == "the yardstick":
                    continue
                calls.setdefault(rec["id"], []).append(verdict)
    print(f"{config}: repeats {repeats}, {trials} trials{' ' + ' '.join(relative) if relative else ''}, "
          f"wall time per run {statistics.median(wall):.1f} s (median)")
    print("| id | 95 % interval / median (median over runs) | same build called slower or faster |")
    print("|---|---:|---:|")
    for alg in sorted(calls):
        w = f"{100 * statistics.median(widths[alg]):.1f} %" if alg in widths else "(needs repeats >= 3)"
        changed = sum(v in ("slower", "faster") for v in calls[alg])
        print(f"| {alg} | {w} | {changed} of {len(calls[alg])} |")


if __name__ == "__main__":
    main()
