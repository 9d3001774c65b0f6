"""Regularize (facaid.regularize) then induce, on the CMP dev half: accuracy against the clean annotation and
compression. Dev half only (facades 1-189, every N-th); evaluation data: nothing here trains.

    .venv/bin/python experiments/2026-12-03-lattice/sweep.py --every 3 [--snap S] [--cross C] [--consensus Q]
        [--perturb SEED] [--sizing] [--json F]
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
    ap.add_argument("--snap", type=float, default=None, help="off when not given")
    ap.add_argument("--cross", type=float, default=0.005)
    ap.add_argument("--consensus", type=float, default=None)
    ap.add_argument("--soft", type=float, default=None)
    ap.add_argument("--every", type=int, default=3)
    ap.add_argument("--perturb", type=int, default=None)
    ap.add_argument("--sizing", action="store_true")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    rows = []
    for i, (rid, seg) in enumerate(load_records(DEFAULT_CMP, 189)[:: args.every]):
        target = rasterize(flatten(seg))
        given = seg if args.perturb is None else annotator_noise(seg, args.perturb * 100_003 + i)
        t0 = time.perf_counter()
        if args.snap is None:
            read = given
        else:
            from facaid.regularize import regularize  # regularize.py of this run, copied into facaid/

            read = regularize(given, snap=args.snap, cross=args.cross)
        proc = induce_procedure(flatten(read), consensus=args.consensus, soft=args.soft)
        if proc is None:
            rows.append({"id": rid, "failed": True})
            continue
        if args.sizing:
            proc = fit_sizes(proc, flatten(given)).procedure
        row = {"id": rid, "accuracy": pixel_accuracy(rasterize(to_segmentation(proc)), target),
               "compression": compression(proc, seg), "seconds": time.perf_counter() - t0}
        if args.perturb is not None:
            row["input_accuracy"] = pixel_accuracy(rasterize(flatten(given)), target)
        rows.append(row)
    ok = [r for r in rows if not r.get("failed")]
    summary = {k: getattr(args, k) for k in ("snap", "cross", "consensus", "soft", "perturb", "sizing")}
    summary.update(facades=len(rows), failed=len(rows) - len(ok),
                   accuracy_mean=float(np.mean([r["accuracy"] for r in ok])),
                   compression_median=float(statistics.median([r["compression"] for r in ok])),
                   seconds_median=float(statistics.median([r["seconds"] for r in ok])))
    if args.perturb is not None:
        summary["input_accuracy_mean"] = float(np.mean([r["input_accuracy"] for r in ok]))
    print(json.dumps(summary))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"summary": summary, "per_facade": rows}, f, indent=1)


if __name__ == "__main__":
    main()
