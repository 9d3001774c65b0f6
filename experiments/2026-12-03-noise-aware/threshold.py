"""For each input: the model's structure alone (best of 4, sized), how much of its disagreement with the input
moved edges cannot explain (`facaid.metrics.unexplained`), whether it has fewer element leaves than the induced
structure, and its accuracy against the clean facade beside the input's own. Evaluation only.

    .venv/bin/python experiments/2026-12-03-noise-aware/threshold.py DATA.jsonl --limit 20 [--perturb 1] --out F
"""

from __future__ import annotations

import argparse
import json

from facaid.augmentation import annotator_noise
from facaid.evaluation.real import load_records
from facaid.grammar.execute import to_segmentation
from facaid.reading.induce import induce_procedure
from facaid.metrics import element_leaves, pixel_accuracy, unexplained
from facaid.pipeline import ReconstructOptions, default_model, reconstruct
from facaid.segmentation import flatten, rasterize


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("data")
    ap.add_argument("--limit", type=int, default=20)
    ap.add_argument("--perturb", type=int, default=None)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    model, tokenizer = default_model()
    with open(args.out, "w") as f:
        for i, (rid, seg) in enumerate(load_records(args.data, args.limit)):
            given = seg if args.perturb is None else annotator_noise(seg, args.perturb * 100_003 + i)
            flat, truth = flatten(given), rasterize(seg)
            r = reconstruct(flat, ReconstructOptions(k=4, induce=False), model=model, tokenizer=tokenizer)
            pred = rasterize(to_segmentation(r.procedure))
            induced = induce_procedure(flat)
            row = {"id": rid, "unexplained": unexplained(pred, rasterize(flat)),
                   "fewer_leaves": induced is None or element_leaves(r.procedure) < element_leaves(induced),
                   "gain": pixel_accuracy(pred, truth) - pixel_accuracy(rasterize(given), truth)}
            f.write(json.dumps(row) + "\n")
            f.flush()


if __name__ == "__main__":
    main()
