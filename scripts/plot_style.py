"""One visual style for every plot of shadowlab (run plots and sweep plots): each algorithm id
keeps one colour everywhere, and each stage (or second grouping) one hatch, line style and marker,
so every (algorithm, stage) pair reads distinctly even when printed in grey.
"""
import matplotlib.colors as mcolors

# Matplotlib's tab10 (colour-blind friendly, distinct in grey) then tab20's lighter set.
COLOURS = list(mcolors.TABLEAU_COLORS.values()) + ["#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94"]
LINESTYLES = ["-", "--", ":", "-."]
MARKERS = ["o", "s", "^", "D", "v", "P", "X", "*"]
HATCHES = ["", "//", "..", "xx", "\\\\", "++", "oo", "--"]


def colours(ids):
    """Colour per algorithm id, in first-seen order."""
    return {i: COLOURS[k % len(COLOURS)] for k, i in enumerate(dict.fromkeys(ids))}


def variants(keys):
    """Line style, marker and hatch per stage (or other grouping), in first-seen order; the first
    gets a solid line and no hatch."""
    out = {}
    for k, key in enumerate(dict.fromkeys(keys)):
        out[key] = {"linestyle": LINESTYLES[k % len(LINESTYLES)], "marker": MARKERS[k % len(MARKERS)],
                    "hatch": HATCHES[k % len(HATCHES)]}
    return out


def shade(colour, k):
    """The colour lightened a little per step k (stacked segments of one bar stay one hue)."""
    r, g, b = mcolors.to_rgb(colour)
    t = min(0.12 * k, 0.5)
    return (r + (1 - r) * t, g + (1 - g) * t, b + (1 - b) * t)
