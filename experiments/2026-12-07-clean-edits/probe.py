"""The lattice reading of CMP dev facades, sized, judged as a person looks at its edits (issue 67), without the
model (on real facades the lattice reading is what the pipeline returns as editable).

    .venv/bin/python experiments/2026-12-07-clean-edits/probe.py --start 0 --limit 40 [--json OUT] [--nosize]
"""
import argparse
import json
import time
from collections import Counter

import numpy as np

from facaid.evaluation.editability import describes, editability, kept_elements, segmentation_lattice
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.grammar.execute import to_segmentation
from facaid.metrics import pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.pipeline import best_reading
from facaid.segmentation import flatten, rasterize

ap = argparse.ArgumentParser()
ap.add_argument("--start", type=int, default=0)
ap.add_argument("--limit", type=int, default=40)
ap.add_argument("--json")
ap.add_argument("--nosize", action="store_true")
args = ap.parse_args()
assert args.start + args.limit <= DEV_FACADES, "the dev half only"
out = []
why = Counter()
for rid, seg in load_records(DEFAULT_CMP, args.limit, args.start):
    flat = flatten(seg)
    target = rasterize(flat)
    t0 = time.perf_counter()
    best = best_reading(flat)
    if best is None:
        out.append({"id": rid, "read": False})
        continue
    proc = read = best.procedure
    t1 = time.perf_counter()
    pred = rasterize(to_segmentation(proc))
    rec = {"id": rid, "read": True, "group": read.meta.get("group"), "seconds": t1 - t0,
           "accuracy": pixel_accuracy(pred, target),
           **editability(proc, segmentation_lattice(seg)), **describes(proc, flat.to_array())}
    rec["drawn"], rec["kept"] = kept_elements(flat.to_array(), target, pred)
    for k in ("floors", "bays"):
        if rec.get("eligible") and not rec[f"{k}_clean"]:
            why[(k, rec.get(f"{k}_why", "no parameter").split(" (")[0])] += 1
    out.append(rec)
    print(rid, f"acc {rec['accuracy']:.3f} floors {rec['floors_clean']} bays {rec['bays_clean']} "
          f"kept {rec['kept']}/{rec['drawn']} fh {rec['floor_height_ok']} tw {rec['tile_width_ok']} "
          f"{rec['seconds']:.1f}s", flush=True)
read = [r for r in out if r["read"]]
el = [r for r in read if r.get("eligible")]
mean = lambda key, rs: float(np.mean([bool(r.get(key)) for r in rs])) if rs else 0.0  # noqa: E731
summary = {"facades": len(out), "read": len(read), "eligible": len(el),
           "floors_clean": mean("floors_clean", el), "bays_clean": mean("bays_clean", el),
           "floors_minus_clean": mean("floors_minus_clean", el), "bays_minus_clean": mean("bays_minus_clean", el),
           "floors_plus_one": mean("floors_plus_one", el), "bays_plus_one": mean("bays_plus_one", el),
           "accuracy": float(np.mean([r["accuracy"] for r in read])),
           "kept": sum(r["kept"] for r in read) / max(1, sum(r["drawn"] for r in read)),
           "nothing_lost": mean("nothing_lost", [dict(r, nothing_lost=r["kept"] == r["drawn"]) for r in read]),
           "floor_height_ok": mean("floor_height_ok", [r for r in read if r["floor_height_ok"] is not None]),
           "tile_width_ok": mean("tile_width_ok", [r for r in read if r["tile_width_ok"] is not None])}
print(json.dumps(summary, indent=1))
for k, v in why.most_common():
    print(v, k)
if args.json:
    with open(args.json, "w") as f:
        json.dump({"summary": summary, "per_facade": out}, f, indent=1)
