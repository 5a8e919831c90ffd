"""The figures of an experiment's per-frame images (DIR/images/, written by the runner):

  images/ID_fNNNN_heat_NAME_labelled.png   each heat map with its colour bar, unit and scale, read
                                           from the legend the runner writes beside it
                                           (ID_fNNNN_heat_NAME.json)
  contact_fNNNN.png                        one sheet per frame with images: the reference's shaded
                                           image, then per algorithm its shaded image, its
                                           difference against the reference and its heat maps

Used by plot_results.py; `frame_figures.py DIR` draws them alone.
"""
import csv
import glob
import json
import os
import re
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")  # headless: no display on CI or servers
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LinearSegmentedColormap, Normalize  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_style  # noqa: E402
from safe_files import open_regular, save_figure  # noqa: E402

plot_style.plain_text()  # ids, heat map names and units are drawn as written: no mathtext

# The colours of framework/metrics/Images.cpp's differenceImage(); grey's brightness is the
# reference's visibility (0.25 + 0.5 v).
DIFF_LEGEND = [("false lit", (1.0, 0.1, 0.1)), ("false shadowed", (0.1, 0.3, 1.0)),
               ("agrees (grey: reference visibility)", (0.5, 0.5, 0.5)), ("not lit by the light", (0.0, 0.0, 0.0))]
IMAGE = re.compile(r"^(?P<id>.+)_f(?P<frame>\d{4,})_(?P<kind>shaded|diff)\.png$")


def heat_legends(directory):
    """Every heat map's legend (the runner's JSON), with the path of its labelled PNG added."""
    out = []
    for path in sorted(glob.glob(os.path.join(glob.escape(directory), "images", "*_heat_*.json"))):
        with open_regular(path) as f:
            legend = json.load(f)
        legend["labelled"] = path[:-len(".json")] + "_labelled.png"
        legend["png"] = os.path.join(os.path.dirname(path), legend["image"])
        out.append(legend)
    return out


def scale_text(legend):
    """Two short lines on the scale: its range and how it was chosen, then what lies above it."""
    lo, hi, unit = legend["min"], legend["max"], legend["unit"]
    if legend["data_max"] <= 0:
        return f"all pixels 0 {unit}\n({legend['scale']} scale {lo:g}–{hi:g})"
    how = "fixed scale" if legend["scale"] == "fixed" else f"p99 of {legend['nonzero_pixels']:,} px > 0"
    text = f"{lo:g}–{hi:g} {unit}: {how}\n"
    if legend["clipped_pixels"]:
        text += f"max {legend['data_max']:g}, {legend['clipped_pixels']:,} px above (top colour)"
    else:
        text += f"max {legend['data_max']:g}"
    return text


# A fixed grid in inches, laid out by hand: matplotlib's layout engines measure every text box and
# took most of the drawing time. A cell is the title band over the image and, for a heat map, its
# colour bar and the bar's labels to the right.
TITLE_IN, TOP_IN, MARGIN_IN = 0.62, 0.42, 0.08
BAR_GAP_IN, BAR_IN, BAR_LABELS_IN = 0.07, 0.13, 0.62


class Grid:
    def __init__(self, rows, cols, image_w, image_h, top=TOP_IN, widest=3.2):
        self.top = top  # room for a figure title
        # The image's width in inches: its pixels at 100 dpi, within [2.4, widest].
        self.panel = max(2.4, min(widest, image_w / 100))
        self.image_h = self.panel * image_h / image_w
        self.cell_w = MARGIN_IN + self.panel + BAR_GAP_IN + BAR_IN + BAR_LABELS_IN
        self.cell_h = TITLE_IN + self.image_h + MARGIN_IN
        self.size = (cols * self.cell_w, rows * self.cell_h + top)

    def axes(self, fig, r, c, bar=False):
        """The image's axes of cell (r, c) and, with bar, the colour bar's beside it."""
        W, H = self.size
        left = c * self.cell_w + MARGIN_IN
        bottom = H - self.top - r * self.cell_h - TITLE_IN - self.image_h
        ax = fig.add_axes([left / W, bottom / H, self.panel / W, self.image_h / H])
        ax.set_axis_off()
        if not bar:
            return ax, None
        cax = fig.add_axes([(left + self.panel + BAR_GAP_IN) / W, bottom / H, BAR_IN / W, self.image_h / H])
        return ax, cax


def draw_heat(ax, cax, legend, title):
    """A heat map panel: the runner's PNG exactly as written, and a colour bar over its scale."""
    ax.imshow(mpimg.imread(legend["png"]), interpolation="nearest", aspect="auto")
    ramp = LinearSegmentedColormap.from_list("shadowlab_heat", legend["ramp"])
    # The bar spans [min, max] of the JSON, the values the ramp's ends stand for; an arrow marks
    # pixels above max, drawn in the top colour.
    mappable = plt.cm.ScalarMappable(norm=Normalize(legend["min"], legend["max"]), cmap=ramp)
    bar = ax.figure.colorbar(mappable, cax=cax, extend="max" if legend["clipped_pixels"] else "neither")
    bar.set_label(legend["unit"] or "value", fontsize=7)
    bar.ax.tick_params(labelsize=6)
    ax.set_title(f"{title}\n{scale_text(legend)}", fontsize=7)


def labelled_heat_maps(legends):
    for legend in legends:
        grid = Grid(1, 1, legend["width"], legend["height"], top=0.0, widest=10.24)
        fig = plt.figure(figsize=grid.size)
        ax, cax = grid.axes(fig, 0, 0, bar=True)
        draw_heat(ax, cax, legend, f"{legend['id']} · {legend['name']} · frame {legend['frame']}")
        save_figure(fig, legend["labelled"], dpi=100)
        plt.close(fig)


def mismatch(directory):
    """(id, frame) -> mismatch ratio of the timed pass's total row (frames.csv), where scored."""
    out = {}
    path = os.path.join(directory, "frames.csv")
    if os.path.exists(path):
        with open_regular(path, newline="") as f:
            for row in csv.DictReader(f):
                if row["stage"] == "total" and row.get("mismatch_ratio"):
                    out[(row["id"], int(row["frame"]))] = float(row["mismatch_ratio"])
    return out


def frame_images(directory, legends):
    """frame -> id -> {"shaded": path, "diff": path, "heat": [legend, …]}."""
    frames = defaultdict(lambda: defaultdict(lambda: {"heat": []}))
    for path in sorted(glob.glob(os.path.join(glob.escape(directory), "images", "*.png"))):
        m = IMAGE.match(os.path.basename(path))
        if m:
            frames[int(m["frame"])][m["id"]][m["kind"]] = path
    for legend in legends:
        frames[legend["frame"]][legend["id"]]["heat"].append(legend)
    for per in frames.values():
        for e in per.values():
            e["heat"].sort(key=lambda legend: legend.get("view_index", 0))  # the algorithm's own order
    return frames


def panels_of(e):
    """A row's panels, left to right: shaded image, difference, heat maps."""
    panels = [(kind, e[kind]) for kind in ("shaded", "diff") if kind in e]
    return panels + [("heat", legend) for legend in e["heat"]]


def draw_diff_legend(ax):
    ax.legend(handles=[Patch(facecolor=col, edgecolor="black", label=name) for name, col in DIFF_LEGEND],
              loc="center", fontsize=7, title="difference image", title_fontsize=8, frameon=False)


def contact_sheet(path, frame, entries, ids, scores):
    """One labelled grid: a row per algorithm id (reference first), panels left to right; the
    legend of the difference colours in the first empty cell (the reference's row has no
    difference image)."""
    rows = [i for i in ids if i in entries]
    panels = {aid: panels_of(entries[aid]) for aid in rows}
    cols = max(len(p) for p in panels.values())
    legend_wanted = any("diff" in entries[aid] for aid in rows)
    if legend_wanted and all(len(p) == cols for p in panels.values()):
        cols += 1
    first = next(what["png"] if kind == "heat" else what for p in panels.values() for kind, what in p)
    h, w = mpimg.imread(first).shape[:2]
    grid = Grid(len(rows), cols, w, h)
    fig = plt.figure(figsize=grid.size)
    shown = ["shaded"] + [what for kind, what in (("diff", "difference against the reference"), ("heat", "heat maps"))
                          if any(k == kind for p in panels.values() for k, _ in p)]
    fig.suptitle(f"Frame {frame}: " + ", ".join(shown), fontsize=10,
                 y=1 - 0.1 / grid.size[1], va="top")
    for r, aid in enumerate(rows):
        for c in range(cols):
            if c >= len(panels[aid]):
                if legend_wanted:
                    draw_diff_legend(grid.axes(fig, r, c)[0])
                    legend_wanted = False
                continue
            kind, what = panels[aid][c]
            ax, cax = grid.axes(fig, r, c, bar=kind == "heat")
            if kind == "shaded":
                ax.imshow(mpimg.imread(what), interpolation="nearest", aspect="auto")
                ax.set_title(f"{aid} · shaded" + (" (ground truth)" if aid == "reference" else ""), fontsize=8)
            elif kind == "diff":
                ax.imshow(mpimg.imread(what), interpolation="nearest", aspect="auto")
                score = scores.get((aid, frame))
                note = "not scored" if score is None else f"{100 * score:.3g} % of lit pixels wrong"
                ax.set_title(f"{aid} · difference\n{note}", fontsize=7)
            else:
                draw_heat(ax, cax, what, f"{aid} · {what['name']}")
    save_figure(fig, path, dpi=100)
    plt.close(fig)


def ordered_ids(directory, frames):
    """Algorithm ids as frames.csv lists them (the reference first, then the config's order)."""
    ids = []
    path = os.path.join(directory, "frames.csv")
    if os.path.exists(path):
        with open_regular(path, newline="") as f:
            ids = list(dict.fromkeys(row["id"] for row in csv.DictReader(f)))
    rest = sorted({i for per in frames.values() for i in per} - set(ids))
    ids += rest
    if "reference" in ids:
        ids.remove("reference")
        ids.insert(0, "reference")
    return ids


def main(directory):
    """Draws every figure; returns (contact sheets, labelled heat maps) as paths relative to DIR,
    each list as {frame: [paths]}."""
    legends = heat_legends(directory)
    labelled_heat_maps(legends)
    frames = frame_images(directory, legends)
    ids = ordered_ids(directory, frames)
    scores = mismatch(directory)
    sheets, heats = {}, defaultdict(list)
    for frame in sorted(frames):
        path = os.path.join(directory, f"contact_f{frame:04d}.png")
        contact_sheet(path, frame, frames[frame], ids, scores)
        sheets[frame] = os.path.relpath(path, directory)
    for legend in legends:
        heats[legend["frame"]].append((legend["id"], legend["name"], os.path.relpath(legend["labelled"], directory)))
    return sheets, heats


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
