"""The report of `facaid evaluate` (`facaid.evaluation.synthetic`): Markdown with its PNG plots (tree edit
distances, production frequencies, the noise curve)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["write_report"]


def write_report(result: dict, out_dir: str | Path, title: str = "Evaluation on generated facades") -> Path:
    """Markdown report with PNG plots; returns the Markdown path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.5))
    keys = list(result["ted"]["histogram"])
    axes[0].bar(keys, [result["ted"]["histogram"][k] for k in keys], color="#3465a4")
    axes[0].set_title("tree edit distance")
    axes[0].set_xlabel("TED")
    nkeys = list(result["ted_normalized"]["histogram"])
    axes[1].bar(nkeys, [result["ted_normalized"]["histogram"][k] for k in nkeys], color="#73d216")
    axes[1].set_title("TED / true tree size")
    axes[1].tick_params(axis="x", rotation=60)
    fig.tight_layout()
    fig.savefig(out / "ted.png", dpi=110)
    plt.close(fig)

    truth, pred = result["productions"]["truth"], result["productions"]["predicted"]
    names = sorted(set(truth) | set(pred), key=lambda k: -truth.get(k, 0))
    x = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(10, 3.5))
    ax.bar(x - 0.2, [truth.get(k, 0) for k in names], 0.4, label="ground truth", color="#3465a4")
    ax.bar(x + 0.2, [pred.get(k, 0) for k in names], 0.4, label="predicted", color="#f57900")
    ax.set_xticks(x, names, rotation=60, ha="right")
    ax.set_yscale("log")
    ax.legend()
    ax.set_title("production frequencies")
    fig.tight_layout()
    fig.savefig(out / "productions.png", dpi=110)
    plt.close(fig)

    pts = [p for p in result["noise"] if p["mean_ted"] is not None]
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot([100 * p["measured"] for p in pts], [p["mean_ted"] for p in pts], "o-", color="#cc0000", label="greedy")
    best = {p["level"]: p["mean_ted"] for p in (result.get("best_of") or {}).get("noise", [])
            if p["mean_ted"] is not None}
    if best:  # the same noisy inputs, so at the greedy curve's measured shares
        both = [p for p in pts if p["level"] in best]
        ax.plot([100 * p["measured"] for p in both], [best[p["level"]] for p in both], "s-", color="#3465a4",
                label=f"best of {result['best_of']['k']}")
        ax.legend()
    ax.set_xlabel("pixels changed (%)")
    ax.set_ylabel("mean TED")
    ax.set_title("noise robustness")
    fig.tight_layout()
    fig.savefig(out / "noise.png", dpi=110)
    plt.close(fig)

    r = result
    lines = [
        f"# {title}",
        "",
        f"{r['count']} held-out generated facades (dataset seed {r['seed']}; {r['skipped_too_long']} skipped as too "
        "long for the model)."
        + (" Decoded floors that repeat are written as one repeat, as the canonical trees are (sizes within "
           f"{100 * r['floor_tolerance']:.0f} %)." if r.get("floor_tolerance") else ""),
        "",
        "| figure | value |",
        "| --- | --- |",
        f"| NLL per token, plain | {r['nll_per_token']['plain']:.4f} |",
        f"| NLL per token, with nullification | {r['nll_per_token']['nullified']:.4f} |",
        f"| validity, constrained | {100 * r['validity']['constrained']:.1f} % |",
        f"| validity, unconstrained ({r['validity']['unconstrained_count']} facades) | "
        + ("not measured |" if r["validity"]["unconstrained"] is None else
           f"{100 * r['validity']['unconstrained']:.1f} % |"),
        f"| exact structure (TED = 0) | {100 * r['exact_structure_rate']:.1f} % |",
        f"| TED ≤ 5 | {100 * r['ted']['le5']:.1f} % |",
        f"| mean TED | {r['ted']['mean']:.2f} |",
        f"| mean normalized TED | {r['ted_normalized']['mean']:.3f} |",
        f"| inference latency, greedy, batch 1 (median / p90) | {r['latency_ms']['median']:.0f} / "
        f"{r['latency_ms']['p90']:.0f} ms |",
        "",
        "## Noise robustness",
        "",
    ]
    if any(p["mean_ted"] is not None for p in r["noise"]):
        lines += ["| target | pixels changed | mean TED | facades |", "| --- | --- | --- | --- |"]
        lines += [f"| {100 * p['level']:.0f} % | {100 * p['measured']:.1f} % | {p['mean_ted']:.2f} | {p['count']} |"
                  for p in r["noise"] if p["mean_ted"] is not None]
    else:
        lines.append("Not measured (`--noise-count 0`).")
    if r.get("best_of"):
        b = r["best_of"]
        k = b["k"]
        c = b.get("ceiling")
        block = [
            "",
            f"Best of {k} (the greedy candidate and {k - 1} samples at temperature {b.get('temperature', 1.0)}, "
            "ranked by how well their execution reproduces the input: pixel accuracy in whole points less a point "
            "per element too many or too few, then likelihood, and the winner composed with the others region by "
            "region; as `facaid.reconstruct` decodes):",
            "",
            "| figure | value |",
            "| --- | --- |",
            f"| exact structure (TED = 0), best of {k} | {100 * b['exact_structure_rate']:.1f} % |",
            f"| TED ≤ 5, best of {k} | {100 * b['ted_le5']:.1f} % |",
            f"| mean TED, best of {k} | {b['ted_mean']:.2f} |",
            f"| inference latency, best of {k}, batch 1 (median / p90) | {b['latency_ms']['median']:.0f} / "
            f"{b['latency_ms']['p90']:.0f} ms |",
        ]
        if c:
            block += [f"| the truth's pick among the trees best of {k} chose from (the ceiling of its ranking): "
                      f"exact / TED ≤ 5 / mean TED | {100 * c['exact_structure_rate']:.1f} % / "
                      f"{100 * c['ted_le5']:.1f} % / {c['ted_mean']:.2f} |"]
        at = lines.index("## Noise robustness") - 1
        lines[at:at] = block
        for name, curve in ((f"best of {k}", b["noise"]), ("the truth's pick", c["noise"] if c else [])):
            noisy = [p for p in curve if p["mean_ted"] is not None]
            if noisy:
                lines += ["", f"Mean TED under noise, {name}: " + ", ".join(
                    f"{100 * p['level']:.0f} %: {p['mean_ted']:.2f}" for p in noisy) + "."]
    lines += ["", "![noise](noise.png)", "", "## Tree edit distance", "", "![ted](ted.png)", ""]
    if r.get("by_style"):
        best_k = r["best_of"]["k"] if r.get("best_of") else None
        head = "| style | facades | exact | TED ≤ 5 | mean TED |"
        columns = [("best_of", f"best of {best_k}"), ("ceiling", "truth's pick")] if best_k else []
        columns = [(key, name) for key, name in columns if all(key in st for st in r["by_style"].values())]
        for _, name in columns:
            head += f" {name}: exact | TED ≤ 5 | mean TED |"
        lines += ["## By style", "", head, "|" + " --- |" * (head.count("|") - 1)]
        for name, st in r["by_style"].items():
            row = f"| {name} | {st['count']} |"
            for f in [st["greedy"]] + [st[key] for key, _ in columns]:
                row += f" {100 * f['exact_structure_rate']:.1f} % | {100 * f['ted_le5']:.1f} % | {f['ted_mean']:.2f} |"
            lines.append(row)
        lines.append("")
    lines += ["## Productions", "", "![productions](productions.png)", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path
