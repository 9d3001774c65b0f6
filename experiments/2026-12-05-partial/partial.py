"""Partial-input conditioning, measured: generated held-out facades with a share of their elements left out (as a
person who has drawn only some of them), reconstructed by the model alone (no induction) and completed by the
heuristic `facaid.complete`, both compared with the clean facade.

Per facade and drop share: the partial input's own pixel accuracy against the clean facade; the model's sized
reconstruction's; the input with `complete`'s proposals (score >= the product's default) painted in; and for
both, the share of the dropped elements' pixels they restore (`restored`) and the share of the pixels the input
got right that they change (`broken`).

    .venv/bin/python experiments/2026-12-05-partial/partial.py --count 30 --drop 0.25 0.5 --out shipped.jsonl

With ``--irregular`` (and ``--edge``) the input's floors and bays are also spaced as irregularly as on CMP and its
edges moved: how far the reconstruction restores the regular facade (``--drop 0``: nothing left out).
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import numpy as np
import torch

from facaid.augmentation import CMP_SPACING_X, CMP_SPACING_Y, annotator_noise
from facaid.completion import complete
from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.grammar.execute import to_segmentation
from facaid.metrics import element_leaves
from facaid.model import load_model
from facaid.paths import DEFAULT_CHECKPOINT
from facaid.pipeline import ReconstructOptions, reconstruct
from facaid.segmentation import Rect, Segmentation, flatten, rasterize


def scores(pred: np.ndarray, clean: np.ndarray, given: np.ndarray) -> dict:
    missing = given != clean
    return {"accuracy": float((pred == clean).mean()),
            "restored": float((pred == clean)[missing].mean()) if missing.any() else 1.0,
            "broken": float((pred != clean)[~missing].mean())}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--checkpoint", default=str(DEFAULT_CHECKPOINT))
    ap.add_argument("--count", type=int, default=40)
    ap.add_argument("--seed", type=int, default=5000, help="dataset seed of the held-out facades")
    ap.add_argument("--drop", type=float, nargs="+", default=[0.25, 0.5])
    ap.add_argument("--edge", type=float, default=0.0, help="annotator edge noise on top (share of the side)")
    ap.add_argument("--irregular", action="store_true", help="floors and bays spaced as on CMP too (spacing_warp)")
    ap.add_argument("--k", type=int, default=4)
    ap.add_argument("--no-heuristic", action="store_true")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    torch.set_num_threads(2)
    model, tok = load_model(args.checkpoint, "cpu")
    spacing = {"spacing": CMP_SPACING_X, "spacing_y": CMP_SPACING_Y} if args.irregular else {}
    rows = []
    with open(args.out, "w") as f:
        for drop in args.drop:
            for i in range(args.count):
                s = generate(sample_seed(args.seed, i))
                clean_seg = flatten(s.segmentation)
                clean = rasterize(clean_seg)
                given = flatten(annotator_noise(s.segmentation, 7919 * i + 1, edge=args.edge, drop=drop, spurious=0,
                                                **spacing))
                given_map = rasterize(given)
                row = {"index": i, "drop": drop, "input": scores(given_map, clean, given_map)}
                t0 = time.perf_counter()
                rec = reconstruct(given, ReconstructOptions(k=args.k, induce=False), model=model, tokenizer=tok)
                row["seconds"] = time.perf_counter() - t0
                row["model"] = scores(rasterize(to_segmentation(rec.procedure)), clean, given_map)
                row["model"]["leaves"] = element_leaves(rec.procedure)
                row["truth_leaves"] = element_leaves(s.procedure)
                if not args.no_heuristic:
                    props = complete(given)
                    added = Segmentation(given.width, given.height, given.rects + tuple(
                        Rect(p["label"] if isinstance(p["label"], int) else _label(p["label"]), p["x0"], p["y0"],
                             p["x1"], p["y1"]) for p in props))
                    row["heuristic"] = scores(rasterize(flatten(added)), clean, given_map)
                    row["heuristic"]["proposals"] = len(props)
                rows.append(row)
                f.write(json.dumps(row) + "\n")
                f.flush()
    for drop in args.drop:
        sel = [r for r in rows if r["drop"] == drop]
        line = [f"drop {drop}: {len(sel)} facades; input {100 * np.mean([r['input']['accuracy'] for r in sel]):.2f} %"]
        for who in ("model", "heuristic"):
            if who in sel[0]:
                line.append(f"{who} {100 * np.mean([r[who]['accuracy'] for r in sel]):.2f} % (restored "
                            f"{100 * np.mean([r[who]['restored'] for r in sel]):.1f} %, broken "
                            f"{100 * np.mean([r[who]['broken'] for r in sel]):.2f} %)")
        line.append(f"model better than input on {sum(r['model']['accuracy'] > r['input']['accuracy'] for r in sel)}"
                    f", worse on {sum(r['model']['accuracy'] < r['input']['accuracy'] for r in sel)}")
        line.append(f"seconds median {statistics.median(r['seconds'] for r in sel):.2f}")
        print("; ".join(line))


def _label(name: str) -> int:
    from facaid.labels import LABELS
    return LABELS.index(name)


if __name__ == "__main__":
    main()
