"""The lattice reader on CMP dev facades, unsized: accuracy, compression, editability, time.

    .venv/bin/python experiments/2026-12-06-lattice-reader/sweep.py [--every 3] [--limit N] [--sized] [--json OUT]
"""
import argparse
import json
import statistics
import time

import numpy as np

from facaid.reading import lattice
from facaid.evaluation.editability import editability, segmentation_lattice
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.grammar.execute import to_segmentation
from facaid.metrics import compression, pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.segmentation import flatten, rasterize

ap = argparse.ArgumentParser()
ap.add_argument("--every", type=int, default=3)
ap.add_argument("--limit", type=int, default=DEV_FACADES)
ap.add_argument("--start", type=int, default=0)
ap.add_argument("--sized", action="store_true")
ap.add_argument("--json")
ap.add_argument("--polish", type=int, default=160, help="fit_sizes polish_steps")
ap.add_argument("--perturb", type=int, help="annotate the input as people do first (seed); score against the clean")
for name in ("JITTER", "LEAF_GAIN", "MIN_AREA", "EDGE", "SLIVER", "COLUMN_SUPPORT", "WHOLE", "ONE_OFF", "DELETE"):
    ap.add_argument(f"--{name.lower()}", type=float)
ap.add_argument("--typical", action="store_true", help="no exceptions but lengths")
ap.add_argument("--no_resize", action="store_true", help="no per-copy size deltas")
args = ap.parse_args()
if args.no_resize:
    lattice._resized = lambda *a, **k: []
lattice.EXCEPTIONS = not args.typical
for name in ("JITTER", "LEAF_GAIN", "MIN_AREA", "EDGE", "SLIVER", "COLUMN_SUPPORT", "WHOLE", "ONE_OFF", "DELETE"):
    if getattr(args, name.lower()) is not None:
        setattr(lattice, name, getattr(args, name.lower()))
records = load_records(DEFAULT_CMP, args.limit)[args.start :: args.every]
out = []
for k, (rid, seg) in enumerate(records):
    flat = flatten(seg)
    target = rasterize(flat)
    given = seg
    if args.perturb is not None:
        from facaid.augmentation import annotator_noise
        given = annotator_noise(seg, args.perturb * 100_003 + k)
    t0 = time.perf_counter()
    proc = lattice.read_lattice(given)
    if proc is not None and args.sized:
        from facaid.sizing import fit_sizes
        proc = fit_sizes(proc, flatten(given), polish_steps=args.polish).procedure
    dt = time.perf_counter() - t0
    ann = segmentation_lattice(seg)
    rec = {"id": rid, "seconds": dt, "lattice": ann, "eligible": ann[0] >= 2 and ann[1] >= 2}
    if args.perturb is not None:
        rec["input_accuracy"] = pixel_accuracy(rasterize(flatten(given)), target)
    if proc is None:
        rec.update(read=False)
    else:
        rec.update(read=True, accuracy=pixel_accuracy(rasterize(to_segmentation(proc)), target),
                   compression=compression(proc, seg), **editability(proc, ann))
    out.append(rec)
    print(rid, {k: (round(v, 3) if isinstance(v, float) else v) for k, v in rec.items() if k != "id"}, flush=True)
el = [r for r in out if r["eligible"]]
read = [r for r in el if r["read"]]
def share(key):
    return sum(1 for r in el if r.get(key)) / max(1, len(el))
print(f"\n{len(out)} facades, {len(el)} eligible, read {len(read)}")
print(f"floors {share('floors'):.3f} bays {share('bays'):.3f} floors+1 {share('floors_plus_one'):.3f} "
      f"bays+1 {share('bays_plus_one'):.3f}")
acc = [r["accuracy"] for r in out if r["read"]]
comp = [r["compression"] for r in out if r["read"]]
if args.perturb is not None:
    print(f"perturbed input {np.mean([r['input_accuracy'] for r in out if r['read']]):.4f} against the clean")
print(f"accuracy mean {np.mean(acc):.4f} (read ones), compression median {statistics.median(comp):.2f}, "
      f"seconds median {statistics.median(r['seconds'] for r in out):.3f}")
if args.json:
    with open(args.json, "w") as f:
        json.dump(out, f, indent=1)
