"""Precision of the photo's repeats by class, NCC and alignment (standing in 0, 1 or 2 of a drawn row and column
of the class), the rule's filter off; only those at NCC >= 0.8 are shown to the annotator.

    .venv/bin/python experiments/2026-12-06-copies/by_alignment.py 9
"""
import collections
import sys

import numpy as np

from facaid import completion
from facaid.completion import complete
from facaid.evaluation import assist
from facaid.evaluation.real import load_records
from facaid.labels import LABEL_ID
from facaid.paths import DEFAULT_CMP
from facaid.photo import appearance, repeats

repeats.MATCH = 0.5
completion.REPEAT_MATCH = (0.5, 0.5, 0.5)
completion.COMPANION_EXTRA = 0.0
stats = collections.defaultdict(lambda: [0, 0])
def iou(b, t):
    ix = np.maximum(0, np.minimum(b[2], t[:, 2]) - np.maximum(b[0], t[:, 0])); iy = np.maximum(0, np.minimum(b[3], t[:, 3]) - np.maximum(b[1], t[:, 1]))
    inter = ix * iy; return inter / ((b[2]-b[0])*(b[3]-b[1]) + (t[:,2]-t[:,0])*(t[:,3]-t[:,1]) - inter)
for rid, seg in load_records(DEFAULT_CMP, 189)[::int(sys.argv[1])]:
    lv = appearance.levels(f"var/cmp_photos/{rid}.jpg", seg.width, seg.height)
    truth = seg.to_array()
    def prop(s, rejected):
        out = complete(s, lv, rejected=rejected)
        arr = s.to_array()
        keep = []
        for p in out:
            if not p["reason"].startswith("repeat"):
                keep.append(p); continue
            ncc = (p["score"] - 0.85) / 0.3 + 0.5
            b = np.array([p["x0"], p["y0"], p["x1"], p["y1"]], float)
            lab = LABEL_ID[p["label"]]
            t = truth[truth[:, 0] == lab, 1:].astype(float)
            ok = len(t) and iou(b, t).max() >= 0.7
            d = arr[arr[:, 0] == lab, 1:].astype(float)
            w, h = b[2] - b[0], b[3] - b[1]
            row = ((np.abs(d[:, 1] - b[1]) <= 0.15 * h) & (np.abs(d[:, 3] - b[3]) <= 0.15 * h)).any()
            col = ((np.abs(d[:, 0] - b[0]) <= 0.15 * w) & (np.abs(d[:, 2] - b[2]) <= 0.15 * w)).any()
            key = (p["label"] if p["label"] in ("window", "sill", "blind", "cornice") else "other", min(9, int(ncc * 10)) / 10, int(row) + int(col))
            stats[key][0 if ok else 1] += 1
            if ncc >= 0.8: keep.append(p)
        return keep
    assist.simulate(seg, prop)
for k in sorted(stats):
    a, r = stats[k]; print(k, a, r, round(a / (a + r), 2))
