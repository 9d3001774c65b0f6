"""Which classes the simulated annotator draws by hand, accepts and rejects (every N-th CMP dev facade).

    .venv/bin/python experiments/2026-12-06-copies/by_class.py 9 [NAME=VALUE ...]
"""
import ast
import collections
import sys

from facaid import completion
from facaid.completion import complete, copies
from facaid.evaluation import assist
from facaid.evaluation.real import load_records
from facaid.labels import LABELS
from facaid.metrics import pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.photo import appearance, repeats
from facaid.segmentation import Segmentation, rasterize

for kv in sys.argv[2:]:
    k, v = kv.split("="); setattr(repeats if hasattr(repeats, k) else (copies if hasattr(copies, k) else completion), k, ast.literal_eval(v))
hand = collections.Counter(); acc = collections.Counter(); total = collections.Counter(); rej = collections.Counter()
for rid, seg in load_records(DEFAULT_CMP, 189)[::int(sys.argv[1])]:
    lv = appearance.levels(f"var/cmp_photos/{rid}.jpg", seg.width, seg.height)
    target = rasterize(seg)
    todo = sorted(seg.rects, key=lambda r: (r.y0, r.x0, r.y1, r.x1, r.label))
    for r in todo: total[LABELS[r.label]] += 1
    drawing, rejected, drawn = [], [], 0
    a = 0.0
    while todo and a < 0.95:
        r = todo.pop(0); drawing.append(r); drawn += 1; hand[LABELS[r.label]] += 1
        if drawn % 3 == 0:
            n0 = len(drawing); r0 = len(rejected)
            props = complete(Segmentation(seg.width, seg.height, tuple(drawing)), lv, rejected=rejected)
            assist._review(props, todo, drawing, rejected, 0.7)
            for d in drawing[n0:]: acc[LABELS[d.label]] += 1
            for d in rejected[r0:]: rej[d["label"]] += 1
        a = pixel_accuracy(rasterize(Segmentation(seg.width, seg.height, tuple(drawing))), target)
    for r in todo: total[LABELS[r.label]] -= 1  # not needed once at 95 %
print("class      needed  by-hand accepted rejected")
for k, v in total.most_common(): print(f"{k:10s} {v:6d} {hand[k]:8d} {acc[k]:8d} {rej[k]:8d}")
