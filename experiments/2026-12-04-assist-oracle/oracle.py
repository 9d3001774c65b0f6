"""How low could completion's effort go on CMP? Oracle proposers run through the bench's simulated annotator.

- lattice: for each element not drawn yet, the box made of the x-interval of a drawn element of its class
  (best-matching column) and the y-interval of another (best-matching row); proposed only where that box
  matches the element (IoU >= 0.7): a perfect chooser of lattice crossings, never wrong.
- copy: the element's true place with the size of a drawn element of its class (best IoU): a perfect
  chooser of where to copy a drawn element, never wrong.
- exact: every true element not drawn yet (the floor of the protocol: effort = the calls' cadence).
    .venv/bin/python experiments/2026-12-04-assist-oracle/oracle.py [--stride 1] [--half dev|test|generated]
"""
import argparse
import statistics

import numpy as np

from facaid.evaluation.assist import simulate
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.labels import LABELS
from facaid.paths import DEFAULT_CMP


def _iou1(a0, a1, b0, b1):
    inter = np.clip(np.minimum(a1, b1) - np.maximum(a0, b0), 0, None)
    return inter / np.maximum(1e-9, (a1 - a0) + (b1 - b0) - inter)


def _box_iou(b, r):
    ix = max(0.0, min(b[2], r.x1) - max(b[0], r.x0))
    iy = max(0.0, min(b[3], r.y1) - max(b[1], r.y0))
    inter = ix * iy
    return inter / ((b[2] - b[0]) * (b[3] - b[1]) + r.area - inter) if inter else 0.0


def oracle(truth, kind):
    def propose(seg, rejected=()):
        drawn = list(seg.rects)
        left = [r for r in truth.rects if not any(d.label == r.label and _box_iou((d.x0, d.y0, d.x1, d.y1), r) >= 0.7
                                                   for d in drawn)]
        out = []
        for r in left:
            same = [d for d in drawn if d.label == r.label]
            if not same:
                continue
            if kind == "exact":
                box = (r.x0, r.y0, r.x1, r.y1)
            else:
                a = np.array([(d.x0, d.y0, d.x1, d.y1) for d in same], float)
                if kind == "lattice":
                    col = a[np.argmax(_iou1(a[:, 0], a[:, 2], r.x0, r.x1))]
                    row = a[np.argmax(_iou1(a[:, 1], a[:, 3], r.y0, r.y1))]
                    box = (col[0], row[1], col[2], row[3])
                else:  # copy: a drawn size at the element's centre
                    w, h = a[:, 2] - a[:, 0], a[:, 3] - a[:, 1]
                    cx, cy = (r.x0 + r.x1) / 2, (r.y0 + r.y1) / 2
                    cands = [(cx - wi / 2, cy - hi / 2, cx + wi / 2, cy + hi / 2) for wi, hi in zip(w, h, strict=True)]
                    box = max(cands, key=lambda b: _box_iou(b, r))
            box = tuple(int(round(float(v))) for v in box)
            if box[2] > box[0] and box[3] > box[1] and _box_iou(box, r) >= 0.7:
                out.append({"label": LABELS[r.label], "x0": box[0], "y0": box[1], "x1": box[2], "y1": box[3]})
        return out
    return propose


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--stride", type=int, default=1)
    ap.add_argument("--half", default="dev", help="dev, test, or generated (12 held-out generated facades)")
    args = ap.parse_args()
    if args.half == "generated":
        from facaid.evaluation.assist import as_drawn
        from facaid.generator import generate
        recs = [(str(seed), as_drawn(generate(seed).segmentation)) for seed in range(5000, 5012)]
    else:
        recs = load_records(DEFAULT_CMP)
        recs = (recs[:DEV_FACADES] if args.half == "dev" else recs[DEV_FACADES:])[:: args.stride]
    for kind in ("exact", "copy", "lattice"):
        s = [simulate(seg, oracle(seg, kind)) for _, seg in recs]
        eff = [x.effort for x in s]
        print(f"{args.half} {kind}: {len(s)} facades, median effort {statistics.median(eff):.3f}, "
              f"mean {statistics.mean(eff):.3f}, drawn {sum(x.drawn for x in s)}, accepted "
              f"{sum(x.accepted for x in s)} of {sum(x.elements for x in s)}", flush=True)


if __name__ == "__main__":
    main()
