"""For each element the simulated annotator draws by hand: was it proposed in the call before, and how close?
(best IoU of a same-class proposal, any score), by class. Every N-th CMP dev facade, with its photo.

    .venv/bin/python experiments/2026-12-06-copies/misses.py 9
"""
import collections
import sys

import numpy as np

from facaid.completion import complete
from facaid.defaults import DEFAULT_MIN_SCORE
from facaid.evaluation import assist
from facaid.evaluation.real import load_records
from facaid.labels import LABEL_ID, LABELS
from facaid.metrics import pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.photo import appearance
from facaid.segmentation import Rect, Segmentation, rasterize

bins = collections.defaultdict(collections.Counter)
for rid, seg in load_records(DEFAULT_CMP, 189)[:: int(sys.argv[1])]:
    lv = appearance.levels(f"var/cmp_photos/{rid}.jpg", seg.width, seg.height)
    target = rasterize(seg)
    todo = sorted(seg.rects, key=lambda r: (r.y0, r.x0, r.y1, r.x1, r.label))
    drawing, rejected, drawn, last = [], [], 0, []
    a = 0.0
    while todo and a < 0.95:
        r = todo.pop(0)
        best, score = 0.0, 0.0
        for p in last:
            if LABEL_ID[p["label"]] != r.label:
                continue
            v = assist._iou(Rect(r.label, p["x0"], p["y0"], p["x1"], p["y1"]), r)
            if v > best:
                best, score = v, p["score"]
        kind = ("none" if best < 0.3 else "located" if best < 0.7 else "hit-low-score" if score < DEFAULT_MIN_SCORE
                else "hit-shown")
        bins[LABELS[r.label]][kind] += 1
        drawing.append(r)
        drawn += 1
        if drawn % 3 == 0:
            props = complete(Segmentation(seg.width, seg.height, tuple(drawing)), lv, rejected=rejected, min_score=0.0)
            last = props
            assist._review([p for p in props if p["score"] >= DEFAULT_MIN_SCORE], todo, drawing, rejected, 0.7)
        a = pixel_accuracy(rasterize(Segmentation(seg.width, seg.height, tuple(drawing))), target)
print("class      by-hand: none  located(IoU .3-.7)  hit-but-low-score  hit-shown(?)")
for k, c in sorted(bins.items(), key=lambda kv: -sum(kv[1].values())):
    print(f"{k:10s} {sum(c.values()):5d} {c['none']:6d} {c['located']:8d} {c['hit-low-score']:8d} {c['hit-shown']:8d}")
