#!/usr/bin/env python3
"""Accuracy against time, one point per algorithm variant, from experiment directories: how much
error each variant trades for its speed, against a baseline whose time is 1 (e.g. bvh_raytrace).

  trade_curve.py OUT.png BASELINE_ID DIR [DIR ...]

Each DIR is an experiment's output (summary.json, frames.csv). Per directory one series, its line
through the best trades (each point more accurate than every faster one): x = the
variant's median `trace`-stage time (or total time when it has no trace stage) divided by the
baseline's of the same run (the runs interleave algorithms frame by frame, so the ratio is the
fair one on a shared machine), y = its largest RMSE over the frames against the reference
(frames.csv). The
reference and the baseline itself are left out. Prints the points as a table too.
"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # headless
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_style  # noqa: E402
from safe_files import open_regular, save_figure  # noqa: E402


def stage_median(algorithm):
    times = algorithm.get("time_ms", {})
    stage = times.get("trace") or times.get("total")
    return stage["median"] if stage else None


def worst_rmse(directory):
    """Largest RMSE over the frames per algorithm id (frames.csv; one row per frame carries it)."""
    worst = {}
    with open_regular(os.path.join(directory, "frames.csv")) as f:
        for row in csv.DictReader(f):
            if row.get("rmse"):
                worst[row["id"]] = max(worst.get(row["id"], 0.0), float(row["rmse"]))
    return worst


def points(directory, baseline):
    with open_regular(os.path.join(directory, "summary.json")) as f:
        summary = json.load(f)
    worst = worst_rmse(directory)
    algorithms = summary["algorithms"]
    if baseline not in algorithms:
        sys.exit(f"trade_curve.py: {directory}/summary.json: no algorithm '{baseline}'")
    base = stage_median(algorithms[baseline])
    out = []
    for name, a in algorithms.items():
        if name in (baseline, "reference") or "accuracy" not in a:
            continue
        t = stage_median(a)
        if t is None or not base:
            continue
        out.append((name, t / base, worst.get(name, a["accuracy"]["rmse"]), t))
    return summary.get("name", os.path.basename(directory)), summary.get("triangles"), out


def main(argv):
    if len(argv) < 4:
        sys.exit(__doc__)
    target, baseline, dirs = argv[1], argv[2], argv[3:]
    series = [points(d, baseline) for d in dirs]
    ids = [p[0] for _, _, pts in series for p in pts]
    colour = plot_style.colours(ids)
    style = plot_style.variants([name for name, _, _ in series])
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for name, triangles, pts in series:
        pts = sorted(pts, key=lambda p: p[1])
        # The line joins the best trades only: each point more accurate than every faster one.
        front, best = [], float("inf")
        for p in pts:
            if p[2] < best:
                front.append(p)
                best = p[2]
        label = f"{name} ({triangles:,} triangles)" if triangles else name
        ax.plot([p[1] for p in front], [p[2] for p in front], color="0.6", linestyle=style[name]["linestyle"], label=label)
        for p in pts:
            ax.scatter(p[1], p[2], color=colour[p[0]], marker=style[name]["marker"], zorder=3)
        print(f"{label}: " + ", ".join(f"{p[0]} {p[1]:.2f}x rmse {p[2]:.3f}" for p in pts))
    for i in dict.fromkeys(ids):
        ax.scatter([], [], color=colour[i], label=i)
    ax.axvline(1.0, color="0.3", linewidth=0.8)
    ax.set_xlabel(f"trace time / {baseline}'s (same run)")
    ax.set_ylabel("RMSE against the same-sample reference (worst frame)")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    save_figure(fig, target, dpi=120)


if __name__ == "__main__":
    main(sys.argv)
