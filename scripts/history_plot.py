#!/usr/bin/env python3
"""The plots of `shadowlab history --out OUT` from OUT/history.json:

  history_time.png       each id's total time run by run (median, 95 % interval as a bar), the runs
                         where a time step starts marked (triangle up: slower, down: faster)
  history_accuracy.png   each id's worst-frame mismatch run by run, accuracy steps marked

The x axis is the run, labelled with its commit (or folder) as history.md's "Runs" table names it.
Labels and ids are drawn as plain text (plot_style), whatever they hold.

Usage: history_plot.py HISTORY.json OUT_DIR
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # headless: no display on CI or servers
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_style  # noqa: E402
from safe_files import open_regular, save_figure  # noqa: E402

MAX_TICK_LABELS = 40  # past this many runs, every k-th run is labelled


def ticks(ax, runs):
    step = max(1, (len(runs) + MAX_TICK_LABELS - 1) // MAX_TICK_LABELS)
    at = list(range(0, len(runs), step))
    ax.set_xticks(at)
    ax.set_xticklabels([f"{i} {runs[i]['label'][:12]}" for i in at], rotation=60, ha="right", fontsize=7)
    ax.set_xlabel("run (commit)")


def mark_steps(ax, steps, measure, series, colour):
    for s in steps:
        if s["measure"] != measure:
            continue
        y = series(s["id"], s["run"])
        if y is None:
            continue
        up = s["direction"] in ("slower", "worse")
        ax.plot([s["run"]], [y], marker="^" if up else "v", markersize=11, color=colour[s["id"]],
                markeredgecolor="black", linestyle="none")


def finish(fig, ax, h, title, path):
    """Title, run labels, grid and legend, then the figure saved (atomically) and closed."""
    ax.set_title(title)
    ticks(ax, h["runs"])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def plot_time(h, out, colour):
    fig, ax = plt.subplots(figsize=(9, 4.8))
    for alg, v in h["ids"].items():
        xs = [i for i, t in enumerate(v["time"]) if t]
        med = [v["time"][i]["median"] for i in xs]
        low = [m - (v["time"][i]["low"] if v["time"][i]["low"] is not None else m) for i, m in zip(xs, med)]
        high = [(v["time"][i]["high"] if v["time"][i]["high"] is not None else m) - m for i, m in zip(xs, med)]
        ax.errorbar(xs, med, yerr=[low, high], label=alg, color=colour[alg], marker="o", markersize=3, capsize=2, linewidth=1)

    def at(alg, run):
        t = h["ids"][alg]["time"][run]
        return t["median"] if t else None
    mark_steps(ax, h["steps"], "time", at, colour)
    ax.set_yscale("log")
    ax.set_ylabel("total time per frame over the yardstick's" if h["relative_to"] else "total time per frame (ms)")
    finish(fig, ax, h, "Total time per run (a triangle: a step starts there)", os.path.join(out, "history_time.png"))


def plot_accuracy(h, out, colour):
    fig, ax = plt.subplots(figsize=(9, 4.2))
    for alg, v in h["ids"].items():
        xs = [i for i, m in enumerate(v["mismatch"]) if m is not None]
        ax.plot(xs, [100 * v["mismatch"][i] for i in xs], label=alg, color=colour[alg], marker="o", markersize=3, linewidth=1)

    def at(alg, run):
        m = h["ids"][alg]["mismatch"][run]
        return None if m is None else 100 * m
    mark_steps(ax, h["steps"], "accuracy", at, colour)
    ax.set_yscale("symlog", linthresh=1e-3)
    ax.set_ylabel("worst-frame mismatch (% of pixels)")
    finish(fig, ax, h, "Accuracy per run (a triangle: a step starts there)", os.path.join(out, "history_accuracy.png"))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open_regular(sys.argv[1]) as f:
        h = json.load(f)
    colour = plot_style.colours(list(h["ids"]))
    plot_time(h, sys.argv[2], colour)
    plot_accuracy(h, sys.argv[2], colour)


if __name__ == "__main__":
    main()
