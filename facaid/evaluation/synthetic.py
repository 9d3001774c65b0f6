"""Evaluation on freshly generated, held-out facades: `facaid evaluate`.

Reports the paper's Table 1 (per-token NLL with and without invalid state nullification), the validity rate
with and without the grammar mask, the exact structure rate, tree edit distance histograms (plain and
normalized by the true tree's size), production frequencies (truth vs prediction), a noise robustness curve
and the inference latency. Held out: the dataset seed differs from training's (1) and validation's (2).
"""

from __future__ import annotations

import statistics
import time
from collections import Counter
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from facaid.decoding import best_of_k, decode
from facaid.defaults import FLOOR_TOLERANCE, TEMPERATURE
from facaid.evaluation.noise import perturb
from facaid.evaluation.ted import tree_edit_distance, tree_size
from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.grammar.procedure import Node
from facaid.model import FacaidModel, batch_inputs, batch_outputs
from facaid.pipeline import fit_to_model
from facaid.tokenizer import TokenGrammar, Tokenizer

NOISE_LEVELS = (0.0, 0.05, 0.10, 0.15, 0.20)


def production(node: Node) -> str:
    return node.label if node.rule == "leaf" else f"{node.rule}_{node.axis}"


@torch.no_grad()
def nll(model: FacaidModel, tokenizer: Tokenizer, examples: list, batch_size: int = 16) -> tuple[float, float]:
    """Mean per-token NLL (nats) of the true sequences: plain, and with invalid tokens nullified (the softmax
    taken over the tokens the grammar allows)."""
    plain_sum = null_sum = 0.0
    tokens = 0
    for i in range(0, len(examples), batch_size):
        chunk = examples[i : i + batch_size]
        rects, mask = batch_inputs([ex["rows"] for ex in chunk])
        ids, local, targets, boxes = batch_outputs([ex["tokens"] for ex in chunk])
        logits, _ = model(rects, mask, ids, local, boxes=boxes)
        logp = torch.log_softmax(logits.float(), -1)
        for b, ex in enumerate(chunk):
            seq = ex["tokens"][0]
            grammar = TokenGrammar(tokenizer.vocab, ex["width"], ex["height"], max_len=len(seq) + 1)
            allowed = []
            for t in seq[1:]:
                allowed.append(grammar.allowed())
                grammar.step(t)
            allowed_t = torch.from_numpy(np.stack(allowed))  # (T, V)
            n = len(seq) - 1
            tgt = targets[b, :n]
            plain_sum -= float(logp[b, :n].gather(1, tgt[:, None]).sum())
            masked = logits[b, :n].float().masked_fill(~allowed_t, float("-inf"))
            null_sum -= float(torch.log_softmax(masked, -1).gather(1, tgt[:, None]).sum())
            tokens += n
    return plain_sum / tokens, null_sum / tokens


def evaluate_synthetic(model: FacaidModel, tokenizer: Tokenizer, count: int, seed: int, *,
                       noise_count: int = 100, unconstrained_count: int = 200, best_of: int = 0,
                       progress: bool = True) -> dict:
    """Figures of the greedy decoder; with ``best_of`` = K > 1 also of best-of-K decoding (the greedy candidate
    and K-1 samples, the one whose execution reproduces the input best), as `facaid.reconstruct` decodes."""
    model.eval()
    examples, skipped, index = [], 0, 0
    while len(examples) < count:
        s = generate(sample_seed(seed, index))
        index += 1
        tokens = tokenizer.encode_target(s.procedure)
        try:
            rows = tokenizer.encode_segmentation(s.segmentation)
        except ValueError:
            skipped += 1
            continue
        if len(tokens[0]) > tokenizer.config.max_out:
            skipped += 1
            continue
        examples.append({"sample": s, "rows": rows, "tokens": tokens, "width": s.procedure.width,
                         "height": s.procedure.height})

    nll_plain, nll_null = nll(model, tokenizer, examples)
    teds, norm, latency = [], [], []
    truth_counts: Counter[str] = Counter()
    pred_counts: Counter[str] = Counter()
    valid_unconstrained = 0
    noise_teds: dict[float, list[int]] = {lv: [] for lv in NOISE_LEVELS}
    noise_measured: dict[float, list[float]] = {lv: [] for lv in NOISE_LEVELS}
    best_teds: list[int] = []
    best_latency: list[float] = []
    best_noise: dict[float, list[int]] = {lv: [] for lv in NOISE_LEVELS}
    for i, ex in enumerate(tqdm(examples, desc="evaluate", disable=not progress)):
        s = ex["sample"]
        t0 = time.perf_counter()
        pred = decode(model, tokenizer, s.segmentation)[0]
        latency.append(time.perf_counter() - t0)
        d = tree_edit_distance(s.procedure.root, pred.procedure.root)
        teds.append(d)
        if best_of > 1:
            t0 = time.perf_counter()
            best = best_of_k(model, tokenizer, s.segmentation, best_of, seed=i)
            best_latency.append(time.perf_counter() - t0)
            best_teds.append(tree_edit_distance(s.procedure.root, best.procedure.root))
        norm.append(d / tree_size(s.procedure.root))
        truth_counts.update(production(n) for _, n in s.procedure.nodes())
        pred_counts.update(production(n) for _, n in pred.procedure.nodes())
        if i < unconstrained_count:
            free = decode(model, tokenizer, s.segmentation, constrained=False)[0]
            valid_unconstrained += free.procedure is not None
        if i < noise_count:
            noise_teds[0.0].append(d)
            noise_measured[0.0].append(0.0)
            if best_of > 1:
                best_noise[0.0].append(best_teds[-1])
            for level in NOISE_LEVELS[1:]:
                noisy, measured = perturb(s.segmentation, level, seed=i)
                noisy = fit_to_model(noisy, tokenizer)  # noise can add pieces
                p = decode(model, tokenizer, noisy)[0]
                noise_teds[level].append(tree_edit_distance(s.procedure.root, p.procedure.root))
                noise_measured[level].append(measured)
                if best_of > 1:
                    p = best_of_k(model, tokenizer, noisy, best_of, seed=i)
                    best_noise[level].append(tree_edit_distance(s.procedure.root, p.procedure.root))

    teds_arr = np.array(teds)
    styles = [ex["sample"].style for ex in examples]
    hist = Counter(min(int(t), 20) for t in teds)
    norm_hist = Counter(min(int(x * 20), 20) for x in norm)  # bins of 0.05
    n_unconstrained = min(unconstrained_count, len(examples))
    best = None
    if best_of > 1:
        b = np.array(best_teds)
        best = {"k": best_of, "temperature": TEMPERATURE, "composed": True,  # `facaid.composition`
                "exact_structure_rate": float((b == 0).mean()),
                "ted_mean": float(b.mean()),
                "ted_le5": float((b <= 5).mean()),
                "latency_ms": {"median": 1000 * statistics.median(best_latency),
                               "p90": 1000 * float(np.percentile(best_latency, 90))},
                "noise": [{"level": lv, "mean_ted": float(np.mean(best_noise[lv])) if best_noise[lv] else None,
                           "count": len(best_noise[lv])} for lv in NOISE_LEVELS]}
    return {
        "count": len(examples),
        "seed": seed,
        "skipped_too_long": skipped,
        "floor_tolerance": FLOOR_TOLERANCE,  # decoded floors alike within it are merged (`decode`)
        "nll_per_token": {"plain": nll_plain, "nullified": nll_null},
        "validity": {"constrained": 1.0, "unconstrained": valid_unconstrained / max(1, n_unconstrained),
                     "unconstrained_count": n_unconstrained},
        "exact_structure_rate": float((teds_arr == 0).mean()),
        "ted": {"mean": float(teds_arr.mean()), "median": float(np.median(teds_arr)),
                "le5": float((teds_arr <= 5).mean()),
                "histogram": {("20+" if k == 20 else str(k)): hist[k] for k in sorted(hist)}},
        "ted_normalized": {"mean": float(np.mean(norm)),
                           "histogram": {f"{k * 0.05:.2f}": norm_hist[k] for k in sorted(norm_hist)}},
        "noise": [{"level": lv, "measured": float(np.mean(noise_measured[lv])) if noise_measured[lv] else None,
                   "mean_ted": float(np.mean(noise_teds[lv])) if noise_teds[lv] else None,
                   "count": len(noise_teds[lv])} for lv in NOISE_LEVELS],
        "latency_ms": {"median": 1000 * statistics.median(latency),
                       "p90": 1000 * float(np.percentile(latency, 90))},
        "productions": {"truth": dict(truth_counts.most_common()), "predicted": dict(pred_counts.most_common())},
        "best_of": best,
        "by_style": by_style(styles, teds, best_teds),
    }


def _ted_figures(teds: list[int]) -> dict:
    t = np.array(teds)
    return {"exact_structure_rate": float((t == 0).mean()), "ted_le5": float((t <= 5).mean()),
            "ted_mean": float(t.mean())}


def by_style(styles: list[str], teds: list[int], best_teds: list[int] | None = None) -> dict:
    """Exact structure rate, TED <= 5 and mean TED per generator style (greedy, and best of K when given)."""
    out = {}
    for name in sorted(set(styles)):
        pick = [i for i, st in enumerate(styles) if st == name]
        out[name] = {"count": len(pick), "greedy": _ted_figures([teds[i] for i in pick])}
        if best_teds:
            out[name]["best_of"] = _ted_figures([best_teds[i] for i in pick])
    return out


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
    ax.plot([100 * p["measured"] for p in pts], [p["mean_ted"] for p in pts], "o-", color="#cc0000")
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
        f"{100 * r['validity']['unconstrained']:.1f} % |",
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
        lines[lines.index("## Noise robustness") - 1:lines.index("## Noise robustness") - 1] = [
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
        noisy = [p for p in b["noise"] if p["mean_ted"] is not None]
        if noisy:
            lines += ["", f"Mean TED under noise, best of {k}: " + ", ".join(
                f"{100 * p['level']:.0f} %: {p['mean_ted']:.2f}" for p in noisy) + "."]
    lines += ["", "![noise](noise.png)", "", "## Tree edit distance", "", "![ted](ted.png)", ""]
    if r.get("by_style"):
        best_k = r["best_of"]["k"] if r.get("best_of") else None
        head = "| style | facades | exact | TED ≤ 5 | mean TED |"
        if best_k:
            head += f" best of {best_k}: exact | TED ≤ 5 | mean TED |"
        lines += ["## By style", "", head, "|" + " --- |" * (head.count("|") - 1)]
        for name, st in r["by_style"].items():
            g = st["greedy"]
            row = (f"| {name} | {st['count']} | {100 * g['exact_structure_rate']:.1f} % | "
                   f"{100 * g['ted_le5']:.1f} % | {g['ted_mean']:.2f} |")
            if best_k and "best_of" in st:
                b = st["best_of"]
                row += (f" {100 * b['exact_structure_rate']:.1f} % | {100 * b['ted_le5']:.1f} % | "
                        f"{b['ted_mean']:.2f} |")
            lines.append(row)
        lines.append("")
    lines += ["## Productions", "", "![productions](productions.png)", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path
