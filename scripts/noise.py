#!/usr/bin/env python3
"""How noisy this machine's timings are, and what `shadowlab compare` can tell apart on it: runs
CONFIG 2 x TRIALS times with `repeats` R and compares run 2k with run 2k+1 (one build against
itself). Prints, per algorithm id:

  - the width of the 95 % interval of its total time within one run (as a share of the median;
    from the passes, so only with R >= 3);
  - the width of compare's interval of the ratio NEW/BASE (from the passes, or with R < 3 from the
    frames paired one to one): the noise a comparison sees;
  - how many of the TRIALS comparisons called it slower or faster (same build: should be none),
    and the threshold (--threshold) that 9 in 10 of them stay within: the change, either way, of
    the 9th smallest |log ratio| (an upper bound: compare also needs the interval and the U test);
  - with --slowdowns: for each slowdown s, in how many of the TRIALS comparisons compare calls it
    slower when NEW's times of that id (passes, frames, means) are multiplied by 1 + s, the rest
    left as measured: the smallest slowdown found in (nearly) every trial is the one compare
    detects reliably on this machine.

And the wall time of a run (the cost of the repetitions).

Usage: scripts/noise.py CONFIG REPEATS TRIALS OUT_DIR [--relative-to ID] [--slowdowns 5,10,20]
                        [--set PATH=VALUE ...]
(argv only: every path and value goes to shadowlab as one argument, never through a shell)
"""
import json
import math
import os
import shutil
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BINARY = os.environ.get("SHADOWLAB_BINARY", os.path.join(HERE, "..", "build", "shadowlab"))


def run(config, repeats, out, extra):
    args = [BINARY, "run", config, "--out", out, "--force", "--no-progress", "--set", f"repeats={repeats}",
            "--set", "output.plots=false", "--set", "output.images_at_frames=[]"] + extra
    done = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode not in (0, 3):
        sys.exit(f"noise: {' '.join(args)} failed: {done.stderr.strip().splitlines()[-1:]}")
    with open(os.path.join(out, "summary.json"), encoding="utf-8") as f:
        return json.load(f)


def compare(base, new, out, relative):
    """compare.json's records by id (compare exits 3 on a regression: that is data here)."""
    subprocess.run([BINARY, "compare", base, new, "--out", out, "--force"] + relative,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "compare.json"), encoding="utf-8") as f:
        return {rec["id"]: rec for rec in json.load(f)["ids"]}


def total(rec):
    t = [s for s in rec.get("time", []) if s["stage"] == "total"]
    return t[0] if t else None


def slowed_copy(src, dst, alg, factor):
    """A copy of run folder SRC (summary and resolved config) with ALG's total times times FACTOR."""
    os.makedirs(dst, exist_ok=True)
    shutil.copy(os.path.join(src, "config.resolved.json"), dst)
    with open(os.path.join(src, "summary.json"), encoding="utf-8") as f:
        s = json.load(f)
    e = s["algorithms"][alg]
    e["time_ms"]["total"] = {k: v * factor if isinstance(v, (int, float)) else v for k, v in e["time_ms"]["total"].items()}
    if "total_ms_per_frame" in e:
        e["total_ms_per_frame"] = [v * factor for v in e["total_ms_per_frame"]]
    if "repetitions" in e:
        e["repetitions"]["time_ms"]["total"] = [v * factor for v in e["repetitions"]["time_ms"]["total"]]
    with open(os.path.join(dst, "summary.json"), "w", encoding="utf-8") as f:
        json.dump(s, f)


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    config, repeats, trials, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    extra = sys.argv[5:]
    relative, slowdowns = [], []
    while extra[:1] in (["--relative-to"], ["--slowdowns"]):
        if extra[0] == "--relative-to":
            relative = extra[:2]
        else:
            slowdowns = [float(v) for v in extra[1].split(",")]
        extra = extra[2:]
    os.makedirs(out, exist_ok=True)
    widths, ratio_widths, calls, wall, changes = {}, {}, {}, [], {}
    detected = {}  # (alg, s) -> trials called slower
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
        for alg, rec in compare(pair[0], pair[1], os.path.join(out, f"t{t}-compare"), relative).items():
            tot = total(rec)
            if not tot or tot["verdict"] == "the yardstick":
                continue
            calls.setdefault(alg, []).append(tot["verdict"])
            if tot.get("ratio"):
                changes.setdefault(alg, []).append(abs(math.log(tot["ratio"])))
            if tot.get("low") is not None:
                ratio_widths.setdefault(alg, []).append(tot["high"] - tot["low"])
            for s in slowdowns:
                slowed = os.path.join(out, f"t{t}b-{alg}-{s:g}")
                slowed_copy(pair[1], slowed, alg, 1 + s / 100)
                verdict = total(compare(pair[0], slowed, slowed + "-compare", relative)[alg])["verdict"]
                detected[(alg, s)] = detected.get((alg, s), 0) + (verdict == "slower")
                shutil.rmtree(slowed)
                shutil.rmtree(slowed + "-compare")
    print(f"{config}: repeats {repeats}, {trials} trials{' ' + ' '.join(relative) if relative else ''}"
          f"{' ' + ' '.join(extra) if extra else ''}; wall time per run {statistics.median(wall):.1f} s (median)")
    head = ("| id | run's 95 % interval / median | compare's ratio interval width | same build called slower or faster |"
            " threshold 9 of 10 stay within |")
    rule = "|---|---:|---:|---:|---:|"
    for s in slowdowns:
        head += f" +{s:g} % found |"
        rule += "---:|"
    print(head)
    print(rule)
    for alg in sorted(calls):
        w = f"{100 * statistics.median(widths[alg]):.1f} %" if alg in widths else "(needs repeats >= 3)"
        rw = f"{100 * statistics.median(ratio_widths[alg]):.1f} %" if alg in ratio_widths else "(none)"
        changed = sum(v in ("slower", "faster") for v in calls[alg])
        c = sorted(changes.get(alg, []))
        within = f"{100 * (math.exp(c[math.ceil(0.9 * len(c)) - 1]) - 1):.1f} %" if c else "(none)"
        row = f"| {alg} | {w} | {rw} | {changed} of {len(calls[alg])} | {within} |"
        for s in slowdowns:
            row += f" {detected.get((alg, s), 0)} of {len(calls[alg])} |"
        print(row)


if __name__ == "__main__":
    main()
