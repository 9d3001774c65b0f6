"""Induction with a consensus fold on the CMP dev half: accuracy against the clean annotation and compression.

    .venv/bin/python experiments/2026-12-03-consensus-fold/sweep.py --consensus 0.6 --every 3 [--perturb 1]
        [--sizing] --json out.json

Dev half only (facades 1-189, every N-th), evaluation data: nothing here trains. Without --sizing the induced
procedure is scored as induced (its lengths are the annotation's); with it, after `fit_sizes`.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import numpy as np

from facaid.augmentation import annotator_noise
from facaid.evaluation.real import load_records
from facaid.grammar.execute import to_segmentation
from facaid.reading.induce import induce_procedure
from facaid.metrics import compression, pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.segmentation import flatten, rasterize
from facaid.sizing import fit_sizes


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--consensus", type=float, default=None)
    ap.add_argument("--tolerance", type=float, default=0.15)
    ap.add_argument("--every", type=int, default=3)
    ap.add_argument("--perturb", type=int, default=None)
    ap.add_argument("--sizing", action="store_true")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    records = load_records(DEFAULT_CMP, 189)[:: args.every]
    rows = []
    for i, (rid, seg) in enumerate(records):
        flat = flatten(seg)
        target = rasterize(flat)
        given = flat if args.perturb is None else flatten(annotator_noise(seg, args.perturb * 100_003 + i))
        t0 = time.perf_counter()
        proc = induce_procedure(given, tolerance=args.tolerance, consensus=args.consensus)
        if proc is None:
            rows.append({"id": rid, "failed": True})
            continue
        if args.sizing:
            proc = fit_sizes(proc, given).procedure
        dt = time.perf_counter() - t0
        acc = pixel_accuracy(rasterize(to_segmentation(proc)), target)
        row = {"id": rid, "accuracy": acc, "compression": compression(proc, seg), "seconds": dt,
               "nodes": sum(1 for _ in proc.root.walk())}
        if args.perturb is not None:
            row["input_accuracy"] = pixel_accuracy(rasterize(given), target)
        rows.append(row)
    ok = [r for r in rows if not r.get("failed")]
    summary = {"consensus": args.consensus, "tolerance": args.tolerance, "perturb": args.perturb,
               "sizing": args.sizing, "facades": len(rows), "failed": len(rows) - len(ok),
               "accuracy_mean": float(np.mean([r["accuracy"] for r in ok])),
               "compression_median": float(statistics.median(r["compression"] for r in ok)),
               "nodes_median": float(statistics.median(r["nodes"] for r in ok)),
               "seconds_median": float(statistics.median(r["seconds"] for r in ok))}
    if args.perturb is not None:
        summary["input_accuracy_mean"] = float(np.mean([r["input_accuracy"] for r in ok]))
    print(json.dumps(summary))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"summary": summary, "facades": rows}, f, indent=1)


if __name__ == "__main__":
    main()
