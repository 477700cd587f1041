#!/usr/bin/python3
"""The exploration report: Table 1, Figure 4, each technique's sections and every sweep, as one HTML page.

Usage: /usr/bin/python3 analysis/report.py DIR
Reads only the CSV/JSON outputs found under DIR and writes DIR/report/index.html with its PNG plots,
a CSV copy of every table, and DIR/report/<sweep>_pareto.csv (every row of the sweep plus its Pareto
marks). The inputs, and the nbsim commands that write them:
  DIR/table1.jsonl                   nbsim bench nbuffer --only build --json-out DIR/table1.jsonl  (--only build,update
                                     adds the incremental updates' table: texels/s, against a rebuild)
  DIR/figure4_map.csv                nbsim nbuffer coverage --size 256x256 --out DIR/figure4_map.png
  DIR/sweeps/NAME/results.csv        nbsim explore SWEEP.json --out DIR/sweeps/NAME  (and sweep.json, technique_results.json)
  DIR/results.csv                    nbsim explore SWEEP.json --out DIR  (DIR is then one sweep, named after it)
  DIR/NAME/NAME.json                 a technique's table: nbsim NAME TRACE... --out DIR/NAME  (or DIR/NAME.json: --out DIR),
                                     rendered by analysis/techniques/NAME/section.py; a technique whose inputs differ
                                     documents them in its section module
The data side (reading, Pareto marks, labels, headline.md) is in report_data.py; plot helpers in
report_plots.py; each technique's sections in analysis/techniques/NAME/section.py. Every section whose
inputs exist is rendered; the page names the inputs the others were missing.
Exit 0 when at least one section rendered; 2 when DIR does not exist or holds nothing usable, or when
an input is malformed (the message names the file; the other sections are still written).
"""
import argparse
import csv
import html
import io
import math
import os
import sys
from pathlib import Path

sys.dont_write_bytecode = True  # no __pycache__ next to the scripts
sys.path.insert(0, str(Path(__file__).resolve().parent))
# report_plots first: it selects matplotlib's headless backend before pyplot loads.
from report_plots import (DPI, FIGSIZE, MAX_LABELLED_POINTS, THOUSANDS, freeze_layout,  # noqa: E402
                          place_labels, spans_decades)
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

import plot_coverage  # noqa: E402
import table1  # noqa: E402
import technique_folders  # noqa: E402
from report_data import (FIDELITY_KNOBS, NUMERIC, BadInput, Missing, fmt, headline_sweep,  # noqa: E402
                         kib_key, technique_results, load_json, mark_pareto, number, pct, read_csv,
                         short_label, trace_name)


def technique_sections():
    """Every technique's report module (analysis/techniques/<name>/section.py), in ORDER: a technique adds
    its sections there, without editing this file. A module has NAME and ORDER, and either TITLE and
    section(rep) (one section, anchor NAME, main input DIR/NAME/NAME.json or DIR/NAME.json) or SECTIONS,
    its sections in page order: (anchor, title, build(rep), main input relative to DIR). build(rep) and
    section(rep) return the section's HTML or raise report_data.Missing / BadInput. INPUTS (optional): the
    paths, relative to DIR, the module looks for (the message when DIR holds nothing usable)."""
    return sorted((m for _, m in technique_folders.load("section.py")), key=lambda m: (m.ORDER, m.NAME))


def section_entries(rep, module):
    """A technique module's sections as (anchor, title, build, main input path), in page order."""
    if hasattr(module, "SECTIONS"):
        return [(anchor, title, lambda build=build: build(rep), rep.root / main)
                for anchor, title, build, main in module.SECTIONS]
    return [(module.NAME, module.TITLE, lambda: module.section(rep),
             rep.technique_table_path(module.NAME) or rep.root / module.NAME / f"{module.NAME}.json")]


def section_inputs(module):
    """The paths (relative to DIR) a technique module looks for."""
    if hasattr(module, "INPUTS"):
        return list(module.INPUTS)
    if hasattr(module, "SECTIONS"):
        return [main for _, _, _, main in module.SECTIONS]
    return [f"{module.NAME}/{module.NAME}.json", f"{module.NAME}.json"]


class Report:
    def __init__(self, root):
        self.root = Path(root)
        self.out = self.root / "report"
        self.sections = []   # (anchor, title, html)
        self.missing = []    # (title, [paths])
        self.errors = []     # messages
        self.inputs = []     # (relative path, section)
        self.versions = set()
        self.headline = []   # Markdown blocks for report/headline.md (what scripts/demo prints)
        self.headline_last = []  # blocks printed after every other one (the techniques' tables)

    def rel(self, p):
        return os.path.relpath(p, self.root)

    def used(self, path, section):
        self.inputs.append((self.rel(path), section))

    def save(self, fig, name):
        fig.savefig(self.out / name, dpi=DPI)
        plt.close(fig)
        return name

    def figure(self, name, caption):
        return (f'<figure><img src="{html.escape(name)}" alt="{html.escape(caption[:80])}">'
                f"<figcaption>{caption}</figcaption></figure>")

    def table(self, name, columns, rows, row_class=None, note=""):
        """columns: (header, key, formatter or None); rows: dicts. Writes name.csv with the raw values."""
        with open(self.out / f"{name}.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow([k for _, k, _ in columns])
            for r in rows:
                w.writerow(["" if r.get(k) is None else r.get(k) for _, k, _ in columns])
        h = ['<table><thead><tr>' + "".join(f"<th>{html.escape(c)}</th>" for c, _, _ in columns) + "</tr></thead><tbody>"]
        for i, r in enumerate(rows):
            cls = row_class(r) if row_class else ""
            cells = []
            for _, k, f in columns:
                v = r.get(k)
                s = f(v) if f else fmt(v)
                num = isinstance(v, (int, float)) and not isinstance(v, bool)
                cells.append(f'<td class="n">{html.escape(s)}</td>' if num else f"<td>{html.escape(s)}</td>")
            h.append(f'<tr class="{cls}">' + "".join(cells) + "</tr>" if cls else "<tr>" + "".join(cells) + "</tr>")
        h.append("</tbody></table>")
        h.append(f'<p class="small">{note}Also as <a href="{name}.csv">{name}.csv</a>.</p>')
        return "\n".join(h)

    def run(self, anchor, title, build, main_input):
        try:
            body = build()
        except Missing as m:
            self.missing.append((title, m.args[0]))
            return
        except BadInput as e:
            self.errors.append(str(e))
            self.sections.append((anchor, title, f'<p class="error">Not rendered: {html.escape(str(e))}</p>'))
            return
        except (KeyError, TypeError, ValueError, IndexError, AttributeError, ZeroDivisionError) as e:
            msg = f"{main_input}: unexpected content ({type(e).__name__}: {e})"
            self.errors.append(msg)
            self.sections.append((anchor, title, f'<p class="error">Not rendered: {html.escape(msg)}</p>'))
            return
        finally:
            plt.close("all")
        self.sections.append((anchor, title, body))
        self.rendered = getattr(self, "rendered", 0) + 1

    # ------------------------------------------------------------------------------ Table 1
    def table1(self):
        path = self.root / "table1.jsonl"
        if not path.exists():
            raise Missing(["table1.jsonl"])
        try:
            text = path.read_text()
            t = table1.table_rows(table1.read_rows(io.StringIO(text)))
            updates = table1.update_table_rows(table1.read_update_rows(io.StringIO(text)))
        except (OSError, UnicodeDecodeError, ValueError) as e:
            raise BadInput(f"{path}: {e}") from e
        if not t:
            raise BadInput(f"{path}: no build results (objects with \"bench\": \"build\" and build_ms)")
        self.used(path, "Table 1")
        cols = [("size", "size", None), ("levels", "levels", None), ("paper levels", "paper_levels", None),
                ("paper, 2005 GPU (ms)", "paper_ms_2005_gpu", None), ("nbsim core, 1 CPU core (ms)", "build_ms", None),
                ("level-by-level copy (ms)", "copy_ms", None), ("build / copy", "ratio", lambda v: f"{v:.2f}")]
        tab = self.table("table1", cols, t)

        fig, ax = plt.subplots(figsize=FIGSIZE, constrained_layout=True)
        x = np.arange(len(t))
        wd = 0.27
        paper = [r["paper_ms_2005_gpu"] or np.nan for r in t]
        ax.bar(x - wd, paper, wd, label="paper, 2005 GPU", color="#999999", hatch="//", edgecolor="white")
        ax.bar(x, [r["build_ms"] for r in t], wd, label="nbsim build, 1 CPU core", color="#b2182b")
        ax.bar(x + wd, [r["copy_ms"] for r in t], wd, label="level-by-level copy (baseline)", color="#6fa8dc")
        for i, r in enumerate(t):
            ax.annotate(f"{r['ratio']:.2f}x copy", (x[i], r["build_ms"]), xytext=(0, 3), textcoords="offset points",
                        ha="center", va="bottom", fontsize=8)
        ax.set_yscale("log")
        ax.set_xticks(x, [f"{r['size']}\n{r['levels']} levels" for r in t])
        ax.set_xlabel("depth map size")
        ax.set_ylabel("full N-buffer build time (ms, log scale)")
        ax.set_title("N-buffer build cost (Décoret 2005, Table 1)")
        ax.grid(axis="y", which="both", alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
        img = self.save(fig, "table1.png")
        update_part = ""
        if updates:  # present when the input came from --only build,update
            ucols = [("size", "size", None), ("dirty rectangle", "dirty", None), ("update (ms)", "update_ms", None),
                     ("texels recomputed", "texels_recomputed", None),
                     ("texels/s", "texels_per_s", lambda v: "-" if v is None else f"{v / 1e6:.0f} M"),
                     ("full rebuild (ms)", "rebuild_ms", None), ("update / rebuild", "ratio", lambda v: f"{v:.3g}")]
            update_part = ("<p>Incremental updates (<code>nbsim bench nbuffer --only build,update</code>): an S x S "
                           "rectangle in the middle of the image changes; texels recomputed over every level, and "
                           "their rate, against a full rebuild in the same run.</p>" +
                           self.table("table1_update", ucols, updates))
        worst = max(t, key=lambda r: r["ratio"])
        return (f"<p>From <code>{self.rel(path)}</code> (<code>nbsim bench nbuffer --only build</code>). "
                "The copy baseline moves exactly the bytes a naive level-by-level build reads and writes, in the same "
                "kind of memory as the levels; "
                "the paper's times are for its 2005 GPU, ours for one CPU core, so compare the shape, and "
                f"build/copy (worst here: {worst['ratio']:.2f} at {worst['size']}).</p>" + tab +
                self.figure(img, "Build time per size, log scale. Read off: how build time grows with the "
                            "number of texels (the paper's and ours), and the label above each red bar: the "
                            "build's cost in units of a plain copy of the same bytes (1.0 would be as cheap as copying).") +
                update_part)

    # ------------------------------------------------------------------------------ Figure 4
    def figure4(self):
        path = self.root / "figure4_map.csv"
        if not path.exists():
            raise Missing(["figure4_map.csv"])
        try:
            W, H, maps, lookups, cases = plot_coverage.load(path)
        except (OSError, UnicodeDecodeError, csv.Error, KeyError, ValueError) as e:
            msg = str(e)
            raise BadInput(msg if msg.startswith(str(path)) else f"{path}: {type(e).__name__}: {msg}") from e
        self.used(path, "Figure 4")
        s = plot_coverage.summary(maps, lookups)
        rows = [{"covering": f"{n}: {plot_coverage.TITLES.get(n, n)}", "mean_extra": v["mean_extra"],
                 "worst_extra": v["worst_extra"], "exact": v["exact_fraction"],
                 "lookups": v["mean_lookups"] if v["mean_lookups"] is not None else float("nan")} for n, v in s.items()]
        cols = [("covering", "covering", None), ("mean extra pixels read (% of the box)", "mean_extra", lambda v: pct(v, 1)),
                ("worst (x the box)", "worst_extra", lambda v: f"{v:.0f}x"),
                ("exact for (% of box sizes)", "exact", pct),
                ("lookups a box (mean)", "lookups", lambda v: "" if v != v else f"{v:.2f}")]
        tab = self.table("figure4", cols, rows)
        shares = plot_coverage.case_shares(maps, cases)
        case_rows = [dict({"case": c["case"], "share": c["share"]}, **{f"extra_{n}": e for n, e in c["extra"].items()})
                     for c in shares]
        case_cols = [("case of Fig. 3", "case", None), ("share of box sizes", "share", pct)] + \
                    [(f"mean extra, {n}", f"extra_{n}", lambda v: pct(v, 1)) for n in maps]
        case_tab = self.table("figure4_cases", case_cols, case_rows)
        plot_coverage.plot(W, H, maps, self.out / "figure4.png")
        sizes = next(iter(s.values()))["sizes"]
        return (f"<p>From <code>{self.rel(path)}</code>: every box size from 1x1 to {W}x{H} "
                f"({sizes:,} sizes), how many pixels beyond the box each covering's squares read.</p>" + tab +
                "<p>The same by the paper's five cases (a property of the box's shape: the case each box falls in).</p>" +
                case_tab +
                self.figure("figure4.png", "Extra pixels read over the box area, log colour scale, x = box width, "
                            "y = box height, one map per covering. Read off: the paper's covering is exact (darkest) "
                            "wherever both sides exceed half the bounding power of two, and its thin rows and columns "
                            "read squares of a quarter of it; the corner squares overhang by up to a whole square on "
                            "thin boxes; one square is looser everywhere."))

    # ------------------------------------------------------------------------------ techniques' sections
    def technique_table_path(self, name):
        """DIR/NAME/NAME.json (the demo's layout) or DIR/NAME.json (nbsim NAME TRACE... --out DIR); None when neither is."""
        for p in (self.root / name / f"{name}.json", self.root / f"{name}.json"):
            if p.is_file():
                return p
        return None

    # ------------------------------------------------------------------------------ sweeps
    def sweep_dirs(self):
        """DIR/sweeps/* (the demo's layout), or DIR itself when it is one `nbsim explore --out` folder."""
        if (self.root / "results.csv").is_file():
            return [self.root.resolve()]  # named after the folder ("." resolved)
        d = self.root / "sweeps"
        return sorted(p for p in d.iterdir() if p.is_dir()) if d.is_dir() else []

    def sweep(self, d):
        path = d / "results.csv"
        if not path.exists():
            raise Missing([f"sweeps/{d.name}/results.csv"])
        meta, params = {}, None
        if (d / "sweep.json").exists():
            meta = load_json(d / "sweep.json")
            if not isinstance(meta, dict) or not isinstance(meta.get("parameters", []), list):
                raise BadInput(f"{d / 'sweep.json'}: expected an object with a \"parameters\" list (nbsim explore)")
            params = [str(p) for p in meta.get("parameters", [])]
            self.used(d / "sweep.json", f"sweep {d.name}")
            if meta.get("nbsim_version"):
                self.versions.add(str(meta["nbsim_version"]))
        # The technique's declared results (technique_results.json): its headline cost and error,
        # the error to fall back on, its memory cost and its correctness count.
        tech = technique_results(d, path)
        lab = tech["report"]
        herr, ferr, hcost, mcost = tech["headline_error"], tech["fallback_error"], tech["headline_cost"], tech["memory_cost"]
        zero = next((m["name"] for m in tech["metrics"] if m.get("must_be_zero")), None)
        header, raw = read_csv(path, ["trace", "status", "cycles_per_frame"])
        has_eff = herr in header
        if not has_eff and ferr not in header:
            raise BadInput(f"{path}: the header lacks {ferr} (or {herr})")
        if params is None:  # without sweep.json: the columns between nbsim_version and status
            i0 = header.index("nbsim_version") + 1 if "nbsim_version" in header else header.index("trace") + 1
            params = header[i0:header.index("status")]
        lacking = [p for p in params if p not in header]
        if lacking:
            raise BadInput(f"{path}: no column for parameter(s) {', '.join(lacking)} that sweep.json lists")
        self.used(path, f"sweep {d.name}")
        rows = []
        for n, r in enumerate(raw, 2):
            rr = dict(r)
            for k in NUMERIC + [m["name"] for m in tech["metrics"]]:
                if k in r:
                    try:
                        rr[k] = number(r[k])
                    except ValueError:
                        if r["status"] == "ok":
                            raise BadInput(f"{path}: line {n}: {k} is not a number: {r[k]!r}")
                        rr[k] = None
            rr["status"] = r["status"].strip() or "?"
            rr["role"] = r.get("role", "").strip() or "sweep"
            rows.append(rr)
        if not rows:
            raise BadInput(f"{path}: no rows")
        ok = [r for r in rows if r["status"] == "ok"]
        traces = list(dict.fromkeys(r["trace"] for r in rows))
        varying = [p for p in params if len({r[p] for r in rows}) > 1]
        fixed = [p for p in params if p not in varying]
        # Labels: a grid (every combination) names every varying value; a list of points names what
        # differs from the trace's first point.
        combos = {tuple(r[p] for p in varying) for r in rows if r["role"] == "sweep"}
        grid = len(combos) == math.prod(len({r[p] for r in rows if r["role"] == "sweep"}) for p in varying) if varying else True
        first = {}
        for r in rows:
            if r["role"] == "sweep":
                first.setdefault(r["trace"], r)
        for r in rows:
            first.setdefault(r["trace"], r)
        for r in rows:
            keys = varying
            if not grid:
                keys = [p for p in varying if r[p] != first[r["trace"]][p]]
            if not keys:  # the first point itself: its mode when the modes differ, else "baseline"
                keys = ["cull.mode"] if "cull.mode" in varying else []
            r["label"] = (short_label(r, keys) or "baseline") if varying else r.get("point_id", "")[:8]
            if r["role"] == "reference":
                r["label"] = "ref " + r["label"]
        # Error: the technique's headline error (in points of %), or 1 - its fallback quality measure.
        use_eff = has_eff and any(r.get(herr) is not None for r in ok)
        if use_eff:
            for r in rows:
                e = r.get(herr)
                r["error_axis"] = None if e is None else 100 * e
            err_label, err_text = lab["error_axis"], lab["error_text"]
        else:
            for r in rows:
                ce = r.get(ferr)
                r["error_axis"] = None if ce is None else 100 * (1 - ce)
            err_label, err_text = lab["fallback_axis"], lab["fallback_text"]
        no_err = sum(1 for r in ok if r["error_axis"] is None)
        for r in rows:
            fe, pe = r.get("fragment_error"), r.get("passed_error")
            r["counter_err"] = r.get("counter_error") if r.get("counter_error") is not None else (
                None if fe is None and pe is None else max(abs(fe or 0), abs(pe or 0)))
        costs = [("cycles_per_frame", "pareto", "cycles per frame", "cycles"),
                 (hcost, lab["cost_pareto"], lab["cost_axis"], lab["cost_short"])]
        if mcost and mcost in header and any(r.get(mcost) is not None for r in ok):
            for r in rows:
                b = r.get(mcost)
                r[kib_key(mcost)] = None if b is None else b / 1024
            costs.append((kib_key(mcost), lab["memory_pareto"], lab["memory_axis"], lab["memory_short"]))
        for key, col, _, _ in costs:
            for r, f in zip(rows, mark_pareto(rows, key, "error_axis")):
                r[col] = f
        # The Pareto CSV: every column of results.csv, then the label, the error and the marks.
        extra = ["label", "error_axis"] + [c for _, c, _, _ in costs]
        with open(self.out / f"{d.name}_pareto.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header + extra)
            for r, rr in zip(raw, rows):
                w.writerow([r[h] for h in header] + [rr["label"], "" if rr["error_axis"] is None else rr["error_axis"]] +
                           ["" if rr[c] is None else ("yes" if rr[c] else "no") for _, c, _, _ in costs])
        # The table of points.
        for r in rows:
            r["trace_short"] = trace_name(r["trace"])
            r["status_text"] = r["status"] + (f": {r['error'][:80]}" if r["status"] != "ok" and r.get("error") else "")
            r["pareto_marks"] = ", ".join(short for _, c, _, short in costs if r.get(c)) or ""
        cols = [("label", "label", None)]
        if len(traces) > 1:
            cols.append(("trace", "trace_short", None))
        if "role" in header:
            cols.append(("role", "role", None))
        cols += [(p, p, None) for p in varying]
        cols += [("status", "status_text", None), ("cycles/frame", "cycles_per_frame", None),
                 (lab["cost_column"], hcost, None)]
        if mcost and any(c[0] == kib_key(mcost) for c in costs):
            cols.append((lab["memory_axis"], kib_key(mcost), None))
        cols += [("memory bytes/frame", "memory_bytes_per_frame", None),
                 (lab["quality_column"], ferr, pct),
                 (lab["error_column"] if use_eff else lab["fallback_column"], "error_axis",
                  lambda v: "-" if v is None else f"{v:.2f}")]
        if zero:
            cols.append((lab["must_be_zero"], zero, None))
        cols += [("counter error", "counter_err", lambda v: "-" if v is None else f"{v:.2%}")]
        if "cycle_error" in header:
            cols.append(("cycle error", "cycle_error", lambda v: "-" if v is None else f"{v:+.3%}" if abs(v) >= 5e-6 else "0.000%"))
        cols += [("host s", "host_seconds", lambda v: "-" if v is None else f"{v:.3f}"),
                 ("Pareto (cost vs error)", "pareto_marks", None)]
        tab = self.table(f"{d.name}_points", cols, rows,
                         row_class=lambda r: "bad" if r["status"] != "ok" or (zero and (r.get(zero) or 0) > 0)
                         else ("pareto" if r["pareto_marks"] else ("ref" if r["role"] == "reference" else "")),
                         note=f"Pareto marks ({', '.join(s for *_, s in costs)}): optimal for that cost against the "
                         f"error, per trace. Every row with its marks: <a href=\"{d.name}_pareto.csv\">{d.name}_pareto.csv</a>. ")
        parts = []
        desc = meta.get("description")
        failed = [r for r in rows if r["status"] != "ok"]
        parts.append(
            f"<p>{html.escape(str(desc)) + ' ' if desc else ''}From <code>{self.rel(path)}</code>"
            f"{' and sweep.json' if meta else ' (no sweep.json: parameters taken from the columns before status)'}: "
            f"{len(rows)} rows over {len(traces)} trace(s) ({', '.join(trace_name(t) for t in traces)}); varying: "
            f"{', '.join(f'<code>{html.escape(p)}</code>' for p in varying) or 'nothing'}"
            f"{'; fixed: ' + ', '.join(f'<code>{html.escape(p)}</code> = {html.escape(str(rows[0][p]))}' for p in fixed) if fixed else ''}. "
            f"Error axis: {err_text}."
            f"{f' {no_err} ok row(s) without it are left out of the plots.' if no_err else ''}"
            f"{'' if grid else ' A list of points: labels name what differs from the baseline, the first point of each trace.'}"
            f"{' <b class=bad>' + str(len(failed)) + ' failed point(s)</b>, listed below, left out of the plots.' if failed else ''}</p>")
        parts.append(tab)
        for key, col, label, short in costs:
            parts.append(self.figure(self.pareto_plot(d.name, rows, traces, key, col, label, err_label, short,
                                                      zero, lab["must_be_zero"]),
                                     f"{label[0].upper() + label[1:]} against the error, one panel per trace. Pareto-optimal points "
                                     "(no other point of the trace is as cheap and as accurate, and strictly better in one) are "
                                     "filled red and joined by the front; grey circles are dominated"
                                     f"{'; stars are reference runs, not in the front' if any(r['role'] == 'reference' for r in rows) else ''}. "
                                     "Read off: the cheapest design for an accepted loss, and what each step down the front costs."))
        self.headline.append(headline_sweep(d.name, rows, traces, err_label, tech))
        speed = self.speed_plot(d.name, rows, params, header)
        if speed:
            parts.append(speed)
        return "\n".join(parts)

    def panels(self, n):
        if n == 1:
            return plt.subplots(figsize=FIGSIZE, constrained_layout=True, squeeze=False)
        cols = min(n, 2)
        nrows = math.ceil(n / cols)
        return plt.subplots(nrows, cols, figsize=(12, 4.8 * nrows), constrained_layout=True, squeeze=False)

    def pareto_plot(self, name, rows, traces, key, col, label, err_label, short, zero=None, zero_label=None):
        """One Pareto panel per trace; zero: the technique's correctness count (must be 0), marked when it is not."""
        fig, axes = self.panels(len(traces))
        flat = axes.ravel()
        label_jobs = []
        for ax, tr in zip(flat, traces):
            pts = [r for r in rows if r["trace"] == tr and r["status"] == "ok"
                   and r.get(key) is not None and r.get("error_axis") is not None]
            front = sorted((r for r in pts if r.get(col)), key=lambda r: (r[key], -r["error_axis"]))
            dom = [r for r in pts if r.get(col) is False]
            ref = [r for r in pts if r["role"] == "reference"]
            if dom:
                ax.scatter([r[key] for r in dom], [r["error_axis"] for r in dom], s=30, facecolors="none",
                           edgecolors="#777777", label="dominated", zorder=2)
            if front:
                ax.plot([r[key] for r in front], [r["error_axis"] for r in front], drawstyle="steps-post",
                        color="#b2182b", lw=1.2, alpha=0.7, zorder=1)
                ax.scatter([r[key] for r in front], [r["error_axis"] for r in front], s=40, color="#b2182b",
                           edgecolors="black", linewidths=0.6, label="Pareto-optimal", zorder=3)
            if ref:
                ax.scatter([r[key] for r in ref], [r["error_axis"] for r in ref], s=90, marker="*", color="#1f4e96",
                           label="reference run", zorder=3)
            bad = [r for r in pts if zero and (r.get(zero) or 0) > 0]
            if bad:
                ax.scatter([r[key] for r in bad], [r["error_axis"] for r in bad], s=110, marker="x", color="red",
                           label=zero_label, zorder=4)
            if spans_decades([r[key] for r in pts]):
                ax.set_xscale("log")
            else:
                ax.xaxis.set_major_locator(MaxNLocator(nbins=6, integer=True))
                ax.xaxis.set_major_formatter(THOUSANDS)
            ax.set_xlabel(label + (" (log scale)" if ax.get_xscale() == "log" else ""))
            ax.set_ylabel(err_label, fontsize=9)
            ax.set_title(trace_name(tr), fontsize=10)
            ax.grid(which="both", alpha=0.3)
            ax.margins(x=0.15, y=0.15)
            if pts:
                ax.legend(fontsize=7, loc="best")
            else:
                ax.text(0.5, 0.5, "no ok point with both values", transform=ax.transAxes, ha="center")
            label_jobs.append((ax, pts))
        for ax in flat[len(traces):]:
            ax.set_visible(False)
        fig.suptitle(f"Sweep {name}: {label} against error (Pareto front per trace)")
        freeze_layout(fig)
        for ax, pts in label_jobs:
            # A crowded panel labels only the points worth naming (the front, references, points whose
            # correctness count is not 0); the sweep's points table names every point.
            crowded = len(pts) > MAX_LABELLED_POINTS
            named = [r for r in pts if not crowded or r.get(col) or r["role"] == "reference"
                     or (zero and (r.get(zero) or 0) > 0)]
            rest = [r for r in pts if not any(r is n for n in named)]
            if named:
                labs = [r["label"] + (f" ({int(r[zero])} {zero_label})" if zero and (r.get(zero) or 0) > 0 else "")
                        for r in named]
                place_labels(ax, [r[key] for r in named], [r["error_axis"] for r in named], labs,
                             avoid=[(r[key], r["error_axis"]) for r in rest])
            if rest:
                ax.text(0.01, 0.01, "dominated points unlabelled: see the points table", transform=ax.transAxes,
                        fontsize=7, color="#777777", ha="left", va="bottom")
        return self.save(fig, f"{name}_{short}_vs_error.png")

    def speed_plot(self, name, rows, params, header):
        """Simulator speed against cycle error, for sweeps of fidelity knobs or with a cycle_error column."""
        knobs = [p for p in params if p in FIDELITY_KNOBS]
        has_ce = "cycle_error" in header and any((r.get("cycle_error") or 0) != 0 for r in rows)
        if not knobs and not has_ce:
            return ""
        ok = [r for r in rows if r["status"] == "ok"]
        if "cycle_error" in header and any(r.get("cycle_error") is not None for r in ok):
            for r in ok:
                r["_ce"] = None if r.get("cycle_error") is None else 100 * abs(r["cycle_error"])
            src = "the cycle_error column (against the same point at the most detailed fidelity settings)"
        else:
            base = {}
            for r in ok:
                base.setdefault(r["trace"], r)
            for r in ok:
                b = base[r["trace"]]["cycles_per_frame"]
                r["_ce"] = None if not b or r["cycles_per_frame"] is None else 100 * abs(r["cycles_per_frame"] / b - 1)
            src = ("cycles per frame against each trace's first point of the sweep (there is no cycle_error column "
                   "yet: this is the change a knob makes, not an error against the most detailed settings)")
        if any(r.get("cycles_per_host_second") is not None for r in ok):
            ykey, ylabel, scale = "cycles_per_host_second", "simulator speed (M simulated cycles per host second)", 1e-6
        else:
            ykey, ylabel, scale = "host_seconds", "host seconds per run (lower is faster)", 1
        pts = [r for r in ok if r.get("_ce") is not None and r.get(ykey) is not None]
        if not pts:
            return ""
        traces = list(dict.fromkeys(r["trace"] for r in pts))
        fig, ax = plt.subplots(figsize=FIGSIZE, constrained_layout=True)
        markers = ["o", "s", "^", "D", "v", "P"]
        for i, tr in enumerate(traces):
            tp = [r for r in pts if r["trace"] == tr]
            ax.scatter([r["_ce"] for r in tp], [r[ykey] * scale for r in tp], marker=markers[i % len(markers)],
                       s=40, color=f"C{i}", edgecolors="black", linewidths=0.5, label=trace_name(tr), zorder=3)
        xs = [r["_ce"] for r in pts]
        pos = [x for x in xs if x > 0]
        if pos and max(pos) / min(pos) >= 30:
            ax.set_xscale("symlog", linthresh=min(pos))
        if spans_decades([r[ykey] for r in pts]):
            ax.set_yscale("log")
        ax.set_xlabel("|cycle error| (% of cycles per frame)")
        ax.set_ylabel(ylabel)
        ax.set_title(f"Sweep {name}: simulator speed against its cycle error")
        ax.grid(which="both", alpha=0.3)
        ax.margins(x=0.2, y=0.2)
        ax.legend(fontsize=8, loc="best", title="trace", title_fontsize=8)
        freeze_layout(fig)
        labs = [r["label"] + (f" (counters {r['counter_err']:.1%} off)" if r.get("counter_err") else "") for r in pts]
        place_labels(ax, xs, [r[ykey] * scale for r in pts], labs, [f"C{traces.index(r['trace'])}" for r in pts])
        img = self.save(fig, f"{name}_speed_vs_cycle_error.png")
        for r in ok:
            r.pop("_ce", None)
        return self.figure(img, f"One marker per point and trace: x = |cycle error|, from {src}; y = "
                           f"{ylabel}. Read off: which fidelity knobs buy speed for how much cycle error; the "
                           "best are up and to the left. Host speed is measured on a shared machine: compare "
                           "points of one run only, and expect noise of tens of percent.")

    # ------------------------------------------------------------------------------ page
    def write_html(self):
        css = """
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; max-width: 1200px; margin: 2em auto;
       padding: 0 1em; color: #222; line-height: 1.45; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
code { background: #f3f3f3; padding: 0 0.25em; border-radius: 3px; font-size: 90%; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 13px; }
th, td { border: 1px solid #d0d0d0; padding: 3px 7px; } th { background: #eef1f5; text-align: left; vertical-align: bottom; }
td.n { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.pareto td { background: #fff3d6; } tr.bad td { background: #fde0e0; } tr.ref td { background: #e6eefb; }
figure { margin: 1.2em 0; } figure img { max-width: 100%; border: 1px solid #e3e3e3; }
figcaption { color: #444; font-size: 90%; max-width: 900px; }
.small { font-size: 85%; color: #555; } .missing { background: #fff8e6; border: 1px solid #f0d9a0; padding: 0.5em 1em; }
.error, .bad { color: #a00; }
"""
        versions = ", ".join(sorted(self.versions)) or "unknown (no input names it)"
        h = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             "<title>nbsim exploration report</title>", f"<style>{css}</style></head><body>",
             "<h1>nbsim exploration report</h1>",
             f"<p>nbsim version {html.escape(versions)}; inputs read from <code>{html.escape(str(self.root.resolve()))}</code>"
             " (paths below are relative to it). Written by <code>analysis/report.py</code> from CSV/JSON outputs only.</p>"]
        h.append("<details><summary>Inputs read</summary><ul>" + "".join(
            f"<li><code>{html.escape(p)}</code> ({html.escape(s)})</li>" for p, s in self.inputs) + "</ul></details>")
        h.append("<ul>" + "".join(f'<li><a href="#{a}">{html.escape(t)}</a></li>' for a, t, _ in self.sections) + "</ul>")
        if self.missing:
            h.append('<div class="missing"><b>Sections not rendered, inputs missing:</b><ul>' + "".join(
                f"<li>{html.escape(t)}: {', '.join(f'<code>{html.escape(p)}</code>' for p in ps)}</li>"
                for t, ps in self.missing) + "</ul></div>")
        for a, t, body in self.sections:
            h.append(f'<h2 id="{a}">{html.escape(t)}</h2>')
            h.append(body)
        h.append("</body></html>")
        (self.out / "index.html").write_text("\n".join(h) + "\n")
        (self.out / "headline.md").write_text("\n\n".join(self.headline + self.headline_last) + "\n")


def main(argv):
    ap = argparse.ArgumentParser(
        description=__doc__.splitlines()[0], epilog="\n".join(__doc__.splitlines()[2:]),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir", metavar="DIR", help="folder holding the nbsim outputs (the demo's out/demo)")
    a = ap.parse_args(argv)
    root = Path(a.dir)
    if not root.is_dir():
        print(f"report: {a.dir}: no such folder", file=sys.stderr)
        return 2
    rep = Report(root)
    try:
        rep.out.mkdir(exist_ok=True)
    except OSError as e:
        print(f"report: cannot create {rep.out}: {e}", file=sys.stderr)
        return 2
    sections = technique_sections()
    # A module's LEADING sections come first, before Table 1: the report's headline.
    for s in sections:
        for anchor, title, build, main_input in getattr(s, "LEADING", []):
            rep.run(anchor, title, lambda b=build: b(rep), root / main_input)
    rep.run("table1", "Table 1: N-buffer build cost", rep.table1, root / "table1.jsonl")
    rep.run("figure4", "Figure 4: covering tightness", rep.figure4, root / "figure4_map.csv")
    for s in sections:
        for anchor, title, build, main_input in section_entries(rep, s):
            rep.run(anchor, title, build, main_input)
    dirs = rep.sweep_dirs()
    if not dirs:
        rep.missing.append(("Sweeps (architecture exploration)", ["sweeps/NAME/results.csv"]))
    for d in dirs:
        rep.run(f"sweep-{d.name}", f"Sweep {d.name}", lambda d=d: rep.sweep(d), d / "results.csv")
    rendered = getattr(rep, "rendered", 0)
    for e in rep.errors:
        print(f"report: {e}", file=sys.stderr)
    if rendered == 0 and not rep.errors:
        try:
            rep.out.rmdir()  # nothing written into it
        except OSError:
            pass
        tables = ", ".join(p for s in sections for p in section_inputs(s))
        print(f"report: nothing usable in {a.dir}: looked for table1.jsonl, figure4_map.csv, "
              f"{tables}, sweeps/NAME/results.csv, results.csv", file=sys.stderr)
        return 2
    rep.write_html()
    print(f"report: wrote {rep.out / 'index.html'} ({rendered} sections"
          f"{'; missing inputs: ' + '; '.join(t for t, _ in rep.missing) if rep.missing else ''})")
    return 2 if rep.errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
