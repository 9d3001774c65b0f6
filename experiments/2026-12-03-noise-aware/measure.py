"""Per input: the induced structure and the model's (alone), each sized against the input, scored against the
input and against the clean facade, with the disagreement the input's own edge noise predicts. Generated
facades (perturbed as people annotate) and CMP dev-half facades (clean and perturbed); evaluation only.

    .venv/bin/python experiments/2026-12-03-noise-aware/measure.py --generated 10 --cmp 10 --out rows.jsonl
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from facaid.augmentation import annotator_noise
from facaid.evaluation.real import load_records
from facaid.generator import generate
from facaid.generator.stats import irregularity
from facaid.grammar.execute import to_segmentation
from facaid.reading.induce import induce_procedure
from facaid.labels import BACKGROUND, FACADE
from facaid.metrics import compression, pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.pipeline import ReconstructOptions, default_model, reconstruct
from facaid.segmentation import flatten, rasterize
from facaid.sizing import fit_sizes


def predicted_noise(seg) -> float:
    """The share of pixels the input's own edge noise would change: every element's edges moved by the mean
    absolute deviation its window rows and columns show (0.85 x their spread)."""
    irr = irregularity([seg])
    dy = 0.85 * 0.5 * (irr["row_top"] + irr["row_bottom"]) * seg.height
    dx = 0.85 * 0.5 * (irr["column_left"] + irr["column_right"]) * seg.width
    rows = flatten(seg, wall="footprint").to_array()
    el = rows[(rows[:, 0] != FACADE) & (rows[:, 0] != BACKGROUND)]
    w, h = el[:, 3] - el[:, 1], el[:, 4] - el[:, 2]
    return float((2 * (w * dy + h * dx)).sum() / (seg.width * seg.height))


def _dilate(mask: np.ndarray, r: int, axis: int) -> np.ndarray:
    """``mask`` grown by ``r`` pixels both ways along ``axis`` (a running box sum)."""
    c = np.cumsum(np.pad(mask.astype(np.int32), [(r + 1, r) if a == axis else (0, 0) for a in range(2)]), axis=axis)
    n = mask.shape[axis]
    hi = np.take(c, np.arange(2 * r + 1, 2 * r + 1 + n), axis=axis)
    lo = np.take(c, np.arange(0, n), axis=axis)
    return (hi - lo) > 0


def unexplained(pred: np.ndarray, given: np.ndarray, edge: float = 0.01) -> float:
    """The share of the image where ``pred`` disagrees with ``given`` farther than ``edge`` x the side (along
    each axis) from any edge of ``given``: disagreement that moved edges cannot explain (whole elements)."""
    h, w = given.shape
    border = np.zeros_like(given, dtype=bool)
    border[:, 1:] |= given[:, 1:] != given[:, :-1]
    border[:, :-1] |= given[:, 1:] != given[:, :-1]
    border[1:, :] |= given[1:, :] != given[:-1, :]
    border[:-1, :] |= given[1:, :] != given[:-1, :]
    band = _dilate(_dilate(border, max(1, round(edge * w)), 1), max(1, round(edge * h)), 0)
    return float(((pred != given) & ~band).mean())


def row(kind, rid, clean, given, model, tokenizer):
    flat, truth = flatten(given), rasterize(clean)
    out = {"kind": kind, "id": rid, "noise": predicted_noise(given),
           "input_vs_clean": pixel_accuracy(rasterize(given), truth)}
    seen = rasterize(flat)
    induced = fit_sizes(induce_procedure(flat), flat).procedure
    r = reconstruct(flat, ReconstructOptions(k=4, induce=False), model=model, tokenizer=tokenizer)
    for name, proc in (("induced", induced), ("model", r.procedure)):
        pred = rasterize(to_segmentation(proc))
        out[name] = {"vs_input": pixel_accuracy(pred, seen), "vs_clean": pixel_accuracy(pred, truth),
                     "compression": compression(proc, given), "unexplained": unexplained(pred, seen)}
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--generated", type=int, default=10)
    ap.add_argument("--cmp", type=int, default=10)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    model, tokenizer = default_model()
    with open(args.out, "w") as f:
        def put(r):
            f.write(json.dumps(r) + "\n")
            f.flush()
            print(json.dumps(r), flush=True)
        for seed in range(args.generated):
            seg = generate(seed).segmentation
            put(row("generated+noise", f"gen{seed}", seg, annotator_noise(seg, seed), model, tokenizer))
        for i, (rid, seg) in enumerate(load_records(DEFAULT_CMP, 189)[:: 189 // max(1, args.cmp)][: args.cmp]):
            put(row("cmp", rid, seg, seg, model, tokenizer))
            put(row("cmp+noise", rid, seg, annotator_noise(seg, 100_003 + i), model, tokenizer))


if __name__ == "__main__":
    main()
