"""Plot helpers of nbsim's exploration report (report.py): figure settings, and labels placed clear of
markers and of each other. Matplotlib runs headless (Agg). A technique's own styles live in its section
module (analysis/techniques/NAME/section.py).
"""
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.transforms  # noqa: E402
from matplotlib.ticker import StrMethodFormatter  # noqa: E402

DPI = 110
THOUSANDS = StrMethodFormatter("{x:,.0f}")
FIGSIZE = (7, 4.5)
# A cost-against-error panel with more points than this labels only its front (readability).
MAX_LABELLED_POINTS = 12


def spans_decades(values, decades=1.0):
    v = [x for x in values if x is not None and x > 0]
    return len(v) > 1 and math.log10(max(v) / min(v)) >= decades


# ------------------------------------------------------------------------------------ plot labels

def place_labels(ax, xs, ys, labels, colors=None, fontsize=7, avoid=()):
    """Annotate points, trying offsets around each until the label overlaps no marker, no earlier label
    and not the axes' border, and sits nearer its own marker than any other; points within a few pixels
    of each other (and of one colour) share one label. Where no offset keeps the label nearest its own
    marker, it gets a leader line to it. `avoid`: (x, y) of markers left unlabelled, kept clear as well.
    Call after the layout is fixed (freeze_layout)."""
    renderer = ax.figure.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    colors = colors or ["#222222"] * len(xs)
    groups = []  # [display x, display y, data x, data y, colour, labels]
    placed = []  # display boxes to keep clear: the markers first, then each label placed
    for x, y, lab, c in zip(xs, ys, labels, colors):
        px, py = ax.transData.transform((x, y))
        placed.append(matplotlib.transforms.Bbox.from_extents(px - 4, py - 4, px + 4, py + 4))
        near = next((g for g in groups if g[4] == c and math.hypot(g[0] - px, g[1] - py) <= 5), None)
        if near is None:
            groups.append([px, py, x, y, c, [lab]])
        else:
            near[5].append(lab)
    others = []  # display positions of the unlabelled markers
    for x, y in avoid:
        px, py = ax.transData.transform((x, y))
        placed.append(matplotlib.transforms.Bbox.from_extents(px - 4, py - 4, px + 4, py + 4))
        others.append((px, py))

    def distance(bb, px, py):
        return math.hypot(max(bb.x0 - px, 0.0, px - bb.x1), max(bb.y0 - py, 0.0, py - bb.y1))

    def nearest_is_own(bb, g):
        mine = distance(bb, g[0], g[1])
        return (all(distance(bb, o[0], o[1]) > mine for o in groups if o is not g)
                and all(distance(bb, px, py) > mine for px, py in others))

    offsets = [(5, 4), (5, -12), (-5, 4), (-5, -12), (6, 14), (6, -22), (-6, 14), (-6, -22),
               (10, -4), (-10, -4), (6, 26), (6, -34), (-6, 26), (-6, -34), (14, 38), (-14, 38)]
    for g in groups:
        x, y, c = g[2], g[3], g[4]
        labs = list(dict.fromkeys(g[5]))
        text = "\n".join(labs) if len(labs) <= 3 else "\n".join(labs[:2] + [f"+{len(labs) - 2} more"])
        chosen = None
        for strict in (True, False):  # second pass: let the label sit nearer another marker, with a leader
            for dx, dy in offsets:
                t = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points", fontsize=fontsize,
                                ha="left" if dx >= 0 else "right", va="bottom", color=c)
                bb = t.get_window_extent(renderer)
                inside = frame.x0 <= bb.x0 and bb.x1 <= frame.x1 and frame.y0 <= bb.y0 and bb.y1 <= frame.y1
                t.remove()
                if inside and not any(bb.overlaps(p) for p in placed) and (not strict or nearest_is_own(bb, g)):
                    chosen = (dx, dy, strict)
                    break
            if chosen:
                break
        dx, dy, clear = chosen or (offsets[0][0], offsets[0][1], False)
        far = abs(dx) + abs(dy) > 20  # a label this far from its marker gets a leader line too
        leader = {} if clear and not far else {"arrowprops": {"arrowstyle": "-", "color": "#999", "lw": 0.5}}
        t = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points", fontsize=fontsize,
                        ha="left" if dx >= 0 else "right", va="bottom", color=c, **leader)
        placed.append(t.get_window_extent(renderer))


def freeze_layout(fig):
    """Run the constrained layout once and keep it, so labels placed afterwards stay where they were put."""
    fig.canvas.draw()
    fig.set_layout_engine("none")
