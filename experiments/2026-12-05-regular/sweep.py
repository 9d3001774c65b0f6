"""Sweep `facaid.regular` on CMP dev facades (evaluation only): accuracy against the annotation, compression."""
import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from facaid.augmentation import annotator_noise
from facaid.evaluation.real import load_records
from facaid.grammar.execute import to_segmentation
from facaid.metrics import compression, element_leaves, pixel_accuracy
from facaid.paths import DEFAULT_CMP

sys.path.insert(0, str(Path(__file__).parent))
from regular import regular_procedure  # noqa: E402

from facaid.segmentation import flatten, rasterize
from facaid.sizing import fit_sizes

ap = argparse.ArgumentParser()
ap.add_argument("--every", type=int, default=3)
ap.add_argument("--limit", type=int, default=189)
ap.add_argument("--eps", type=float, nargs="+", default=[0.1])
ap.add_argument("--tau", type=float, default=0.03)
ap.add_argument("--tolerance", type=float, default=0.15)
ap.add_argument("--lookahead", type=int, default=2)
ap.add_argument("--sliver", type=float, default=0.004)
ap.add_argument("--sizing", action="store_true")
ap.add_argument("--perturb", type=int)
ap.add_argument("--out")
args = ap.parse_args()
records = load_records(DEFAULT_CMP, args.limit)[:: args.every]
rows = []
for eps in args.eps:
    acc, comp, secs, inp = [], [], [], []
    for i, (rid, seg) in enumerate(records):
        flat = flatten(seg)
        target = rasterize(flat)
        given = seg if args.perturb is None else annotator_noise(seg, args.perturb * 100_003 + i * args.every)
        gflat = flatten(given)
        t0 = time.perf_counter()
        proc = regular_procedure(gflat, eps=eps, tau=args.tau, tolerance=args.tolerance, lookahead=args.lookahead, sliver=args.sliver)
        if proc is None:
            print(rid, "none")
            continue
        if args.sizing:
            proc = fit_sizes(proc, gflat).procedure
        secs.append(time.perf_counter() - t0)
        a = pixel_accuracy(rasterize(to_segmentation(proc)), target)
        acc.append(a)
        comp.append(compression(proc, given))
        inp.append(pixel_accuracy(rasterize(gflat), target))
        rows.append({"id": rid, "eps": eps, "accuracy": a, "compression": comp[-1], "leaves": element_leaves(proc),
                     "input": inp[-1], "seconds": secs[-1]})
    print(f"eps {eps}: {len(acc)} facades, accuracy mean {100*np.mean(acc):.2f} % (input {100*np.mean(inp):.2f}), "
          f"compression median {statistics.median(comp):.2f}, {statistics.median(secs):.2f} s median")
if args.out:
    with open(args.out, "w") as f:
        for r in rows:
            f.write(json.dumps(r) + "\n")
