import sys, statistics, time
import numpy as np
from facaid.evaluation.real import load_records
from facaid.paths import DEFAULT_CMP
from facaid.induce import induce_procedure
from facaid.metrics import compression, pixel_accuracy
from facaid.grammar.execute import to_segmentation
from facaid.segmentation import flatten, rasterize
la = int(sys.argv[1]); cons = None if sys.argv[2] == "none" else float(sys.argv[2])
recs = load_records(DEFAULT_CMP, 189)[::6]
acc, comp, ts = [], [], []
for rid, seg in recs:
    flat = flatten(seg); t=time.perf_counter()
    p = induce_procedure(flat, lookahead=la, consensus=cons); ts.append(time.perf_counter()-t)
    acc.append(pixel_accuracy(rasterize(to_segmentation(p)), rasterize(flat))); comp.append(compression(p, seg))
print(la, cons, f"acc {np.mean(acc):.4f} comp {statistics.median(comp):.3f} t {statistics.median(ts):.2f}s")
