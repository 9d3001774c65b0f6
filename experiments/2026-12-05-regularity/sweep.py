"""Sizing that trades pixels for regularity, measured on the induced structure: induction's fold tolerance (siblings
whose lengths agree within it become one repeat of their average: equal floors, equal tiles) and its snap (edges
this close become one line) loosened step by step, each structure sized against the annotation. Every 3rd facade
of the CMP dev half (evaluation data: nothing is trained or tuned into the product).

    .venv/bin/python experiments/2026-12-05-regularity/sweep.py --every 3 --out sweep.jsonl
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from facaid.evaluation.real import load_records
from facaid.reading.induce import induce_procedure
from facaid.metrics import compression, element_leaves
from facaid.paths import DEFAULT_CMP
from facaid.segmentation import flatten
from facaid.sizing import fit_sizes

SETTINGS = [(0.01, 0.15), (0.01, 0.3), (0.01, 0.5), (0.02, 0.3), (0.02, 0.5), (0.03, 0.5)]  # (snap, tolerance)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--every", type=int, default=3)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    records = load_records(DEFAULT_CMP, 189)[:: args.every]
    rows = []
    with open(args.out, "w") as f:
        for rid, seg in records:
            flat = flatten(seg)
            for snap, tolerance in SETTINGS:
                t0 = time.perf_counter()
                proc = induce_procedure(flat, snap=snap, tolerance=tolerance)
                if proc is None:
                    continue
                fitted = fit_sizes(proc, flat)
                row = {"id": rid, "snap": snap, "tolerance": tolerance, "accuracy": fitted.accuracy,
                       "compression": compression(fitted.procedure, seg), "leaves": element_leaves(fitted.procedure),
                       "seconds": time.perf_counter() - t0}
                rows.append(row)
                f.write(json.dumps(row) + "\n")
    for snap, tolerance in SETTINGS:
        sel = [r for r in rows if (r["snap"], r["tolerance"]) == (snap, tolerance)]
        acc = 100 * np.mean([r["accuracy"] for r in sel])
        print(f"snap {snap} tolerance {tolerance}: {len(sel)} facades, accuracy {acc:.2f} %"
              f", compression median {np.median([r['compression'] for r in sel]):.2f}, "
              f"{sum(r['compression'] >= 4 for r in sel)} at 4 or more")


if __name__ == "__main__":
    main()
