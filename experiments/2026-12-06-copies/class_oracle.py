"""What perfect copies of some classes would buy: the simulated annotator with `complete` and, beside it, an
oracle that proposes every true element of the given classes not drawn yet (its true box) once one of its class is
drawn. Every N-th CMP dev facade with its photo.

    .venv/bin/python experiments/2026-12-06-copies/class_oracle.py 9 window [pillar ...]
"""
import statistics
import sys

import numpy as np

from facaid.completion import complete
from facaid.evaluation.assist import _iou, simulate
from facaid.evaluation.real import load_records
from facaid.labels import LABEL_ID, LABELS
from facaid.paths import DEFAULT_CMP
from facaid.photo import appearance

classes = {LABEL_ID[c] for c in sys.argv[2:]}
eff, acc, rej = [], 0, 0
for rid, seg in load_records(DEFAULT_CMP, 189)[:: int(sys.argv[1])]:
    lv = appearance.levels(f"var/cmp_photos/{rid}.jpg", seg.width, seg.height)

    def propose(drawing, rejected, seg=seg, lv=lv):
        out = [p for p in complete(drawing, lv, rejected=rejected) if LABEL_ID[p["label"]] not in classes]
        have = {r.label for r in drawing.rects}
        for t in seg.rects:
            if t.label in classes and t.label in have and not any(
                    d.label == t.label and _iou(d, t) > 0.5 for d in drawing.rects):
                out.append({"label": LABELS[t.label], "x0": t.x0, "y0": t.y0, "x1": t.x1, "y1": t.y1, "score": 1.0})
        return out

    s = simulate(seg, propose)
    eff.append(s.effort)
    acc += s.accepted
    rej += s.rejected
print(sys.argv[2:], "effort", round(statistics.median(eff), 3), "accepted", acc, "rejected", rej)
