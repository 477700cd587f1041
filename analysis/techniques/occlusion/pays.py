"""The N-buffer unit that pays: the reading of pipeline/sweeps/nbuffer_techniques.json's results.csv (one
N-buffer design replayed on every technique with an N-buffer unit), shared by docs/exploration.md (docs.py,
block occlusion/techniques) and the report's leading section (section.py).

    summarize(rows) -> (per technique: {technique, best, best_cycles, best_error, default_cycles, default_error,
                        others: [(label, cycles, error)]}, the sentence across the techniques)

rows: results.csv rows of status ok, role sweep (the other roles are left out by the caller).
"""
import math

# Per technique: its trace, its error column, the prefix of its N-buffer units' keys, and the key
# and value that select its N-buffer culling (other values: its other culling).
TECHNIQUE_TRACES = (("occlusion culling", "city_walk_512", "efficiency_lost", "nbuffer", "cull.mode", "nb_hier"),
                    ("particles", "particles_walk", "efficiency_lost", "nbuffer", "particles.mode", "nb"),
                    ("shadows", "shadows_city", "culled_lost_fraction", "litmap_min", None, None))


def design_of(r, prefix):
    clear = "fast clear" if r[f"{prefix}.fast_clear"] == "true" else "clear writes"
    return f"{r[f'{prefix}.update_policy']}, {clear}, div {r[f'{prefix}.resolution_divisor']}, {r[f'{prefix}.format']}"


def other_of(r, mode_key, nb_value):
    if not mode_key or r[mode_key] == nb_value:
        return ""
    m = r[mode_key]
    return m + (f" {r['hiz.tile_px']}x{r['hiz.tile_px']}" if m == "hiz_tile" else "")


def summarize(rows):
    per, ratio = [], {}
    for name, trace, err, prefix, mode_key, nb_value in TECHNIQUE_TRACES:
        rs = [r for r in rows if trace in r["trace"]]
        if not rs:
            continue
        nb = [r for r in rs if not other_of(r, mode_key, nb_value)]
        default = next((r for r in nb if design_of(r, prefix) == "eager, clear writes, div 1, f32"), None)
        if default is None:
            continue
        error = lambda r: float(r[err] or 0)
        # The cheapest design that errs no more than the default (full resolution: no loss).
        best = min((r for r in nb if error(r) <= error(default)), key=lambda r: float(r["cycles_per_frame"]))
        per.append({"technique": name, "best": design_of(best, prefix), "best_cycles": float(best["cycles_per_frame"]),
                    "best_error": error(best), "default_cycles": float(default["cycles_per_frame"]), "default_error": error(default),
                    "others": [(other_of(r, mode_key, nb_value), float(r["cycles_per_frame"]), error(r))
                               for r in rs if other_of(r, mode_key, nb_value)]})
        for r in nb:
            ratio.setdefault(design_of(r, prefix), []).append((float(r["cycles_per_frame"]) / float(default["cycles_per_frame"]),
                                                              error(r) - error(default)))
    full = [d for d, v in ratio.items() if len(v) == len(per)]
    if not full:
        return per, "No design ran on every technique."
    mean = {d: (math.exp(sum(math.log(c) for c, _ in ratio[d]) / len(ratio[d])), max(e for _, e in ratio[d])) for d in full}
    lossless = {d: v for d, v in mean.items() if v[1] <= 0}
    cheapest = min(mean, key=lambda d: mean[d][0])
    sentence = ("Errors in points of %: culling efficiency lost (occlusion culling, particles) and casters culled fewer than the "
                "reference (shadows). Across the techniques (geometric mean of each one's cycles over its default design's), ")
    if lossless:
        overall = min(lossless, key=lambda d: lossless[d][0])
        sentence += f"the cheapest design that loses nothing anywhere is {overall}: {mean[overall][0]:.3f}x; "
    sentence += f"the cheapest of all, {cheapest}: {mean[cheapest][0]:.3f}x, losing up to {100 * mean[cheapest][1]:.2f} points."
    return per, sentence
