"""Paired comparison of two evaluation runs: `facaid compare A.jsonl B.jsonl`.

Two weights evaluated on the same held-out facades (`facaid evaluate --records`, same seed) differ by less than
the spread of one draw of a few hundred facades, so their summary figures alone cannot tell a gain from luck.
Compared facade by facade the spread of the draw cancels: for each figure, how many facades B decodes better
and how many worse than A, and the mean change of the tree edit distance with a bootstrap 95 % interval over
the facades (B − A: negative is better).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from facaid.evaluation.records import RecordsError, read_records
from facaid.evaluation.synthetic import NOISE_LEVELS, ted_figures

BOOTSTRAP = 2000


def paired(a: list[float], b: list[float], seed: int = 0) -> dict:
    """Figures of A and B on the same facades (TED lists in the same order) and the paired change B − A."""
    d = np.asarray(b, dtype=float) - np.asarray(a, dtype=float)
    rng = np.random.default_rng(seed)
    means = d[rng.integers(0, len(d), size=(BOOTSTRAP, len(d)))].mean(1)
    lo, hi = np.quantile(means, [0.025, 0.975])
    return {"count": len(d), "a": ted_figures(a), "b": ted_figures(b), "better": int((d < 0).sum()),
            "worse": int((d > 0).sum()), "mean_change": float(d.mean()), "interval": [float(lo), float(hi)]}


def compare_records(path_a: str | Path, path_b: str | Path) -> dict:
    """The paired figures of two records files of the same held-out facades: greedy, best of K (where both
    measured it) overall and by style, and each noise level (on the facades both measured under noise)."""
    (sa, ra), (sb, rb) = read_records(path_a), read_records(path_b)
    if sa["seed"] != sb["seed"]:
        raise RecordsError(f"the runs read different facades (seed {sa['seed']} and {sb['seed']}): "
                           "compare runs of the same --seed")
    a, b = {r["index"]: r for r in ra}, {r["index"]: r for r in rb}
    common = sorted(set(a) & set(b))
    if not common:
        raise RecordsError("the two runs have no facade in common")
    out: dict = {"seed": sa["seed"], "count": len(common), "a": str(path_a), "b": str(path_b),
                 "same_model": sa.get("model") == sb.get("model"), "figures": {}}
    figures = out["figures"]
    figures["greedy"] = paired([a[i]["ted"] for i in common], [b[i]["ted"] for i in common])
    best = [i for i in common if "best" in a[i] and "best" in b[i]]
    if best:
        figures["best"] = paired([a[i]["best"]["ted"] for i in best], [b[i]["best"]["ted"] for i in best])
        for style in sorted({a[i]["style"] for i in best}):
            rows = [i for i in best if a[i]["style"] == style]
            figures[f"best, {style}"] = paired([a[i]["best"]["ted"] for i in rows], [b[i]["best"]["ted"] for i in rows])
    noisy = [i for i in common if a[i].get("noise") and b[i].get("noise")]
    for j, level in enumerate(NOISE_LEVELS[1:] if noisy else ()):
        name = f"{round(100 * level)} % noise"
        figures[f"{name}, greedy"] = paired([a[i]["noise"][j][0] for i in noisy], [b[i]["noise"][j][0] for i in noisy])
        if all(a[i]["noise"][j][2] is not None and b[i]["noise"][j][2] is not None for i in noisy):
            figures[f"{name}, best"] = paired([a[i]["noise"][j][2] for i in noisy],
                                              [b[i]["noise"][j][2] for i in noisy])
    return out


def format_comparison(result: dict) -> str:
    """A Markdown table of `compare_records`."""
    lines = [f"{result['count']} facades of seed {result['seed']}: A = {result['a']}, B = {result['b']}"
             + (" (the same weights)" if result["same_model"] else ""), "",
             "| figure | facades | A: exact / TED ≤ 5 / mean TED | B: exact / TED ≤ 5 / mean TED | B better | B worse "
             "| mean TED change (95 % interval) |", "| --- | --- | --- | --- | --- | --- | --- |"]

    def rates(r: dict) -> str:
        return f"{100 * r['exact_structure_rate']:.1f} % / {100 * r['ted_le5']:.1f} % / {r['ted_mean']:.2f}"

    for name, f in result["figures"].items():
        lo, hi = f["interval"]
        lines.append(f"| {name} | {f['count']} | {rates(f['a'])} | {rates(f['b'])} | {f['better']} | {f['worse']} "
                     f"| {f['mean_change']:+.2f} ({lo:+.2f} to {hi:+.2f}) |")
    return "\n".join(lines)
