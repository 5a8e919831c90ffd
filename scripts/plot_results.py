#!/usr/bin/env python3
"""Plots of an experiment directory (frames.csv): frame time along the fly-through per algorithm
(as in the metric-tree paper's Figure 11) and accuracy against the reference along the fly-through.

Usage: plot_results.py DIR [gpu|wall]   (writes DIR/plot_frame_time.png, DIR/plot_stages.png, DIR/plot_accuracy.png;
       "wall": stage times from the cpu_ms column, as summary.json's stage_time_source says for CPU rasterisers)
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")  # headless: no display on CI or servers
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_style  # noqa: E402


def load(path, wall):
    total = defaultdict(dict)     # id -> frame -> row of the "total" stage
    stages = defaultdict(lambda: defaultdict(list))  # id -> stage -> [ms per frame]
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["stage"] == "total":
                total[row["id"]][int(row["frame"])] = row
            else:
                # "wall": a CPU rasteriser's timer queries are unreliable, its stages' wall clocks are not
                ms = row["cpu_ms"] if wall else (row["gpu_ms"] or row["cpu_ms"])
                stages[row["id"]][row["stage"]].append(float(ms))
    return total, stages


def main(directory, time_source="gpu"):
    total, stages = load(f"{directory}/frames.csv", time_source == "wall")
    ids = list(total)
    colour = plot_style.colours(ids)

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i in ids:
        frames = sorted(total[i])
        ax.plot(frames, [float(total[i][f]["cpu_ms"]) for f in frames], label=i, color=colour[i])
    ax.set_xlabel("frame")
    ax.set_ylabel("visibility time per frame (ms, wall clock)")
    ax.set_yscale("log")
    ax.set_title("Frame time along the fly-through")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(f"{directory}/plot_frame_time.png", dpi=120)
    plt.close(fig)

    # Stacked bars: the bar's colour is its algorithm, a segment's hatch (and shade) its stage, and
    # one stage name keeps one hatch in every bar, so no two (algorithm, stage) pairs look alike.
    fig, ax = plt.subplots(figsize=(8, 4.5))
    style = plot_style.variants(s for i in ids for s in stages[i])
    labels = []
    for x, i in enumerate(ids):
        bottom = 0.0
        for k, (stage, values) in enumerate(stages[i].items()):
            mean = sum(values) / len(values)
            ax.bar(x, mean, bottom=bottom, color=plot_style.shade(colour[i], k), hatch=style[stage]["hatch"],
                   edgecolor="black", linewidth=0.6)
            bottom += mean
        labels.append(i)
    handles = [Patch(facecolor="white", edgecolor="black", hatch=style[st]["hatch"], label=st) for st in style]
    if handles:
        ax.legend(handles=handles, title="stage", fontsize="small")
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels, rotation=20)
    ax.set_ylabel("mean time per frame (ms; GPU where timed)")
    ax.set_title("Per-stage time")
    fig.tight_layout()
    fig.savefig(f"{directory}/plot_stages.png", dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(8, 4.5))
    plotted = False
    for i in ids:
        frames = [f for f in sorted(total[i]) if total[i][f]["mismatch_ratio"] != ""]
        if not frames or total[i][frames[0]]["algorithm"] == "reference":
            continue
        ax.plot(frames, [100.0 * float(total[i][f]["mismatch_ratio"]) for f in frames], label=i, color=colour[i])
        plotted = True
    ax.set_xlabel("frame")
    ax.set_ylabel("mismatch against the reference (% of lit pixels)")
    ax.set_title("Accuracy along the fly-through")
    ax.grid(True, alpha=0.3)
    if plotted:
        ax.legend()
    fig.tight_layout()
    fig.savefig(f"{directory}/plot_accuracy.png", dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    main(*sys.argv[1:])
