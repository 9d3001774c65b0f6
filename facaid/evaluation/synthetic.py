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
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from facaid.augmentation import perturb
from facaid.decoding import decode, ranked_candidates
from facaid.defaults import FLOOR_TOLERANCE, TEMPERATURE
from facaid.evaluation.records import RecordLog, model_digest
from facaid.evaluation.ted import tree_edit_distance, tree_size
from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.grammar.nodes import Node
from facaid.model import FacaidModel, batch_inputs, batch_outputs
from facaid.pipeline import fit_to_model
from facaid.segmentation import Segmentation
from facaid.tokenizer import TokenGrammar, Tokenizer

NOISE_LEVELS = (0.0, 0.05, 0.10, 0.15, 0.20)
NLL_BATCH = 16  # examples per forward pass of the NLL


def production(node: Node) -> str:
    return node.label if node.rule == "leaf" else f"{node.rule}_{node.axis}"


@torch.no_grad()
def nll_sums(model: FacaidModel, tokenizer: Tokenizer, examples: list, batch_size: int = NLL_BATCH
             ) -> list[tuple[float, float, int]]:
    """Per example: the summed NLL (nats) of its true sequence, plain and with invalid tokens nullified (the
    softmax taken over the tokens the grammar allows), and how many tokens were predicted."""
    out = []
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
            plain = -float(logp[b, :n].gather(1, tgt[:, None]).sum())
            masked = logits[b, :n].float().masked_fill(~allowed_t, float("-inf"))
            out.append((plain, -float(torch.log_softmax(masked, -1).gather(1, tgt[:, None]).sum()), n))
    return out


def nll(model: FacaidModel, tokenizer: Tokenizer, examples: list, batch_size: int = NLL_BATCH) -> tuple[float, float]:
    """Mean per-token NLL (nats) of the true sequences: plain, and with invalid tokens nullified."""
    sums = nll_sums(model, tokenizer, examples, batch_size)
    tokens = sum(n for _, _, n in sums)
    return sum(p for p, _, _ in sums) / tokens, sum(q for _, q, _ in sums) / tokens


def held_out(tokenizer: Tokenizer, seed: int, start: int = 0) -> Iterator[dict]:
    """The held-out facades of dataset ``seed`` from dataset index ``start`` on, as examples (``index``,
    ``sample``, ``rows``, ``tokens``, ``width``, ``height``); facades the model cannot read or write (too many
    rectangles, too long a sequence) are passed over."""
    index = start
    while True:
        s = generate(sample_seed(seed, index))
        index += 1
        tokens = tokenizer.encode_target(s.procedure)
        try:
            rows = tokenizer.encode_segmentation(s.segmentation)
        except ValueError:
            continue
        if len(tokens[0]) > tokenizer.config.max_out:
            continue
        yield {"index": index - 1, "sample": s, "rows": rows, "tokens": tokens, "width": s.procedure.width,
               "height": s.procedure.height}


def best_of_teds(model: FacaidModel, tokenizer: Tokenizer, seg: Segmentation, truth: Node, k: int, seed: int,
                 ceiling: bool) -> tuple[int, int | None, float]:
    """The tree edit distance of best-of-K's choice; with ``ceiling`` the least one among the trees it chose
    from (the K candidates and their composition: what a ranking that knew the truth would reach), else None;
    and the seconds best of K took (decoding and ranking, not the distances)."""
    t0 = time.perf_counter()
    ranked = ranked_candidates(model, tokenizer, seg, k, seed=seed)
    seconds = time.perf_counter() - t0
    chosen = tree_edit_distance(truth, ranked[0].procedure.root)
    if not ceiling:
        return chosen, None, seconds
    others = {tuple(c.ids): c for c in ranked[1:]}  # samples often repeat one another: each tree measured once
    return chosen, min([chosen] + [tree_edit_distance(truth, c.procedure.root) for c in others.values()]), seconds


def measure(model: FacaidModel, tokenizer: Tokenizer, ex: dict, i: int, sums: tuple[float, float, int], *,
            noise_count: int, unconstrained_count: int, best_of: int, ceiling: bool = False) -> dict:
    """The figures of the ``i``-th held-out example as one JSON-ready record (`summarize` adds them up).
    Sampling and noise are seeded by ``i``, so a record does not depend on the run that made it, but for its
    latencies. With ``ceiling``, best of K's records also hold the ceiling of its ranking (`best_of_teds`)."""
    s = ex["sample"]
    truth = s.procedure.root
    t0 = time.perf_counter()
    pred = decode(model, tokenizer, s.segmentation)[0]
    rec: dict = {"i": i, "index": ex["index"], "style": s.style, "nll": list(sums),
                 "latency": time.perf_counter() - t0, "ted": tree_edit_distance(truth, pred.procedure.root),
                 "size": tree_size(truth),
                 "truth": dict(Counter(production(n) for _, n in s.procedure.nodes())),
                 "predicted": dict(Counter(production(n) for _, n in pred.procedure.nodes()))}
    if best_of > 1:
        ted, least, seconds = best_of_teds(model, tokenizer, s.segmentation, truth, best_of, i, ceiling)
        rec["best"] = {"latency": seconds, "ted": ted, **({"ceiling": least} if ceiling else {})}
    if i < unconstrained_count:
        free = decode(model, tokenizer, s.segmentation, constrained=False)[0]
        rec["unconstrained_valid"] = free.procedure is not None
    if i < noise_count:
        # per level of NOISE_LEVELS[1:]: [TED, pixels changed, TED best of K or None(, its ceiling)]
        rec["noise"] = []
        for level in NOISE_LEVELS[1:]:
            noisy, measured = perturb(s.segmentation, level, seed=i)
            noisy = fit_to_model(noisy, tokenizer)  # noise can add pieces
            d = tree_edit_distance(truth, decode(model, tokenizer, noisy)[0].procedure.root)
            b, c = best_of_teds(model, tokenizer, noisy, truth, best_of, i, ceiling)[:2] if best_of > 1 else (None,) * 2
            rec["noise"].append([d, measured, b, c] if ceiling else [d, measured, b])
    return rec


def evaluate_synthetic(model: FacaidModel, tokenizer: Tokenizer, count: int, seed: int, *,
                       noise_count: int = 100, unconstrained_count: int = 200, best_of: int = 0,
                       ceiling: bool = False, progress: bool = True, records: str | Path | None = None) -> dict:
    """Figures of the greedy decoder; with ``best_of`` = K > 1 also of best-of-K decoding (the greedy candidate
    and K-1 samples, the one whose execution reproduces the input best), as `facaid.reconstruct` decodes. With
    ``ceiling`` (and best of K), also the figures of the best tree among those best of K chose from, known from
    the truth: how far a better ranking of the same candidates could take it (`best_of_teds`).

    With ``records`` (a JSON-lines file), each facade's figures are appended to it as they are measured, and a
    run started again on the same file with the same settings and weights goes on where the last one stopped
    (`facaid.evaluation.records`); the figures are then those of one uninterrupted run, but for latency."""
    model.eval()
    settings = {"seed": seed, "noise_count": noise_count, "unconstrained_count": unconstrained_count,
                "best_of": best_of, "temperature": TEMPERATURE, "floor_tolerance": FLOOR_TOLERANCE,
                "model": model_digest(model, tokenizer)}
    ceiling = ceiling and best_of > 1
    if ceiling:  # only then, so that the records files of runs without it still resume
        settings["ceiling"] = True
    log = RecordLog(records, settings) if records is not None else None
    done = log.records[:count] if log else []
    examples = held_out(tokenizer, seed, start=done[-1]["index"] + 1 if done else 0)
    bar = tqdm(total=count, initial=len(done), desc="evaluate", disable=not progress)
    while len(done) < count:
        chunk = [next(examples) for _ in range(min(NLL_BATCH, count - len(done)))]
        for ex, sums in zip(chunk, nll_sums(model, tokenizer, chunk), strict=True):
            rec = measure(model, tokenizer, ex, len(done), sums, noise_count=noise_count,
                          unconstrained_count=unconstrained_count, best_of=best_of, ceiling=ceiling)
            if log:
                log.append(rec)
            done.append(rec)
            bar.update()
    bar.close()
    return summarize(done, seed, best_of)


def summarize(records: list[dict], seed: int, best_of: int = 0) -> dict:
    """The figures of `evaluate_synthetic` from the records of `measure`, in order."""
    if not records:
        raise ValueError("no facades measured")
    teds = np.array([r["ted"] for r in records])
    norm = [r["ted"] / r["size"] for r in records]
    tokens = sum(r["nll"][2] for r in records)
    truth_counts: Counter[str] = Counter()
    pred_counts: Counter[str] = Counter()
    for r in records:
        truth_counts.update(r["truth"])
        pred_counts.update(r["predicted"])
    noisy = [r for r in records if "noise" in r]
    free = [r["unconstrained_valid"] for r in records if "unconstrained_valid" in r]
    hist = Counter(min(int(t), 20) for t in teds)
    norm_hist = Counter(min(int(x * 20), 20) for x in norm)  # bins of 0.05
    latency = [r["latency"] for r in records]
    best_teds = [r["best"]["ted"] for r in records] if best_of > 1 else []
    ceiling_teds = ([r["best"]["ceiling"] for r in records]
                    if best_of > 1 and all("ceiling" in r["best"] for r in records) else [])

    def noise_curve(clean: str | None, column: int) -> list[list[float]]:
        """Per level, the TEDs of the noisy facades: at 0 % their clean TED (``r["ted"]``, or ``r["best"][clean]``),
        then column ``column`` of each level's record (0 greedy, 2 best of K, 3 its ceiling)."""
        first = [r["ted"] if clean is None else r["best"][clean] for r in noisy]
        return [first] + [[r["noise"][j][column] for r in noisy] for j in range(len(NOISE_LEVELS) - 1)]

    def mean_teds(curve: list[list[float]]) -> list[dict]:
        return [{"level": lv, "mean_ted": float(np.mean(t)) if t else None, "count": len(t)}
                for lv, t in zip(NOISE_LEVELS, curve, strict=True)]

    measured = [[0.0] * len(noisy)] + [[r["noise"][j][1] for r in noisy] for j in range(len(NOISE_LEVELS) - 1)]
    best = None
    if best_of > 1:
        blat = [r["best"]["latency"] for r in records]
        best = {"k": best_of, "temperature": TEMPERATURE, "composed": True,  # `facaid.decoding.composition`
                **ted_figures(best_teds),
                "latency_ms": {"median": 1000 * statistics.median(blat),
                               "p90": 1000 * float(np.percentile(blat, 90))},
                "noise": mean_teds(noise_curve("ted", 2))}
        if ceiling_teds:
            best["ceiling"] = {**ted_figures(ceiling_teds), "noise": mean_teds(noise_curve("ceiling", 3))}
    curve = noise_curve(None, 0)
    return {
        "count": len(records),
        "seed": seed,
        "skipped_too_long": records[-1]["index"] + 1 - len(records),
        "floor_tolerance": FLOOR_TOLERANCE,  # decoded floors alike within it are merged (`decode`)
        "nll_per_token": {"plain": sum(r["nll"][0] for r in records) / tokens,
                          "nullified": sum(r["nll"][1] for r in records) / tokens},
        "validity": {"constrained": 1.0, "unconstrained": sum(free) / len(free) if free else None,
                     "unconstrained_count": len(free)},
        "exact_structure_rate": float((teds == 0).mean()),
        "ted": {"mean": float(teds.mean()), "median": float(np.median(teds)),
                "le5": float((teds <= 5).mean()),
                "histogram": {("20+" if k == 20 else str(k)): hist[k] for k in sorted(hist)}},
        "ted_normalized": {"mean": float(np.mean(norm)),
                           "histogram": {f"{k * 0.05:.2f}": norm_hist[k] for k in sorted(norm_hist)}},
        "noise": [{"level": lv, "measured": float(np.mean(m)) if t else None,
                   "mean_ted": float(np.mean(t)) if t else None, "count": len(t)}
                  for lv, t, m in zip(NOISE_LEVELS, curve, measured, strict=True)],
        "latency_ms": {"median": 1000 * statistics.median(latency),
                       "p90": 1000 * float(np.percentile(latency, 90))},
        "productions": {"truth": dict(truth_counts.most_common()), "predicted": dict(pred_counts.most_common())},
        "best_of": best,
        "by_style": by_style([r["style"] for r in records], teds.tolist(), best_teds, ceiling_teds),
    }


def ted_figures(teds: list[int]) -> dict:
    """Exact structure rate, TED <= 5 and mean TED of a list of tree edit distances."""
    t = np.array(teds)
    return {"exact_structure_rate": float((t == 0).mean()), "ted_le5": float((t <= 5).mean()),
            "ted_mean": float(t.mean())}


def by_style(styles: list[str], teds: list[int], best_teds: list[int] | None = None,
             ceiling_teds: list[int] | None = None) -> dict:
    """Exact structure rate, TED <= 5 and mean TED per generator style (greedy, and best of K and its ceiling
    when given)."""
    out = {}
    for name in sorted(set(styles)):
        pick = [i for i, st in enumerate(styles) if st == name]
        out[name] = {"count": len(pick), "greedy": ted_figures([teds[i] for i in pick])}
        for key, values in (("best_of", best_teds), ("ceiling", ceiling_teds)):
            if values:
                out[name][key] = ted_figures([values[i] for i in pick])
    return out
