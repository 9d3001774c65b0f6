"""Lookahead 2 or 3 with a consensus fold, every 6th dev facade (needs consensus-fold.patch applied).

    .venv/bin/python experiments/2026-12-03-consensus-fold/look.py LOOKAHEAD CONSENSUS|none
"""

import statistics
import sys
import time

import numpy as np

from facaid.evaluation.real import load_records
from facaid.grammar.execute import to_segmentation
from facaid.reading.induce import induce_procedure
from facaid.metrics import compression, pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.segmentation import flatten, rasterize

lookahead = int(sys.argv[1])
consensus = None if sys.argv[2] == "none" else float(sys.argv[2])
acc, comp, seconds = [], [], []
for _, seg in load_records(DEFAULT_CMP, 189)[::6]:
    flat = flatten(seg)
    t0 = time.perf_counter()
    proc = induce_procedure(flat, lookahead=lookahead, consensus=consensus)
    seconds.append(time.perf_counter() - t0)
    acc.append(pixel_accuracy(rasterize(to_segmentation(proc)), rasterize(flat)))
    comp.append(compression(proc, seg))
print(lookahead, consensus, f"acc {np.mean(acc):.4f} comp {statistics.median(comp):.3f} "
      f"t {statistics.median(seconds):.2f}s")
