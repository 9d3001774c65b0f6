"""What per-copy geometry alone buys: every copy of every unit with its own sizes (free parameters for the
sizing, no leaves), no relabels, no own trees, no variants. A bound for "typical topology, each copy sized".

    .venv/bin/python experiments/2026-12-07-copy-geometry/probe.py [--every 9] [--mode typical|geometry]
"""
import argparse
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
from facaid.sizing import fit_sizes

ap = argparse.ArgumentParser()
ap.add_argument("--every", type=int, default=9)
ap.add_argument("--mode", default="geometry")
ap.add_argument("--leaf_gain", type=float)
ap.add_argument("--settle", type=float)
ap.add_argument("--polish", type=int, default=160)
args = ap.parse_args()

if args.leaf_gain:
    lattice.LEAF_GAIN = args.leaf_gain


def all_sizes(node, path=()):
    if node.rule == "leaf":
        return []
    out = [((*path, i), s) for i, s in enumerate(node.sizes)] if node.rule == "split" else []
    for i, c in enumerate(node.children):
        if c.rule != "leaf" and node.rule == "split":
            out += all_sizes(c, (*path, i))
    return out


if args.mode in ("geometry", "typical"):
    lattice._Choice.worth = lambda self, gain, cost: False
if args.mode == "geometry":
    lattice._Choice.own = lambda self, ref, crop: [(p, s, None) for p, s in all_sizes(ref.tree)]
if args.mode == "hybrid":
    _own = lattice._Choice.own

    def hybrid(self, ref, crop):
        deltas = _own(self, ref, crop)
        if any(p == () for p, _, n in deltas):
            return deltas
        taken = {p for p, _, _ in deltas}
        return deltas + [(p, s, None) for p, s in all_sizes(ref.tree) if p not in taken]
    lattice._Choice.own = hybrid
if args.mode == "typical":
    lattice._Choice.own = lambda self, ref, crop: []
def settle(proc, tol):
    """After sizing: each size that copies override takes the median of their values as its shared one; the
    overrides within ``tol`` pixels of it go (jitter, restored by the shared size)."""
    from facaid.grammar.procedure import Size
    from facaid.grammar.repeats import along_path
    for _, rep in list(proc.root.walk()):
        if rep.rule != "repeat" or not rep.exceptions:
            continue
        groups = {}
        for o in rep.exceptions:
            if o.node is not None or o.size is None or len(o.path) < 2:
                continue
            node = next((t for k, t in along_path(rep, o, rep.exceptions) if k == len(o.path) - 2), None)
            if node is None or node.rule != "split":
                continue
            groups.setdefault((id(node), o.path[-1]), (node, []))[1].append(o)
        drop = set()
        for node, items in groups.values():
            i = items[0].path[-1]
            if i >= len(node.sizes) or any(o.size.mode != node.sizes[i].mode for o in items):
                continue
            med = float(np.median([o.size.value for o in items]))
            node.sizes[i] = Size(node.sizes[i].mode, med)
            drop |= {id(o) for o in items if abs(o.size.value - med) <= tol}
        rep.exceptions = [o for o in rep.exceptions if id(o) not in drop]
    return proc


acc, comp, fl, ba, secs = [], [], [], [], []
for rid, seg in load_records(DEFAULT_CMP, DEV_FACADES)[:: args.every]:
    t0 = time.perf_counter()
    proc = lattice.read_lattice(seg)
    if proc is None:
        print(rid, "unread")
        continue
    unsized = pixel_accuracy(rasterize(to_segmentation(proc)), rasterize(flatten(seg)))
    proc = fit_sizes(proc, flatten(seg), polish_steps=args.polish).procedure
    if args.settle is not None:
        from facaid.grammar.procedure import Procedure
        proc = settle(proc, args.settle * min(proc.width, proc.height))
        proc = Procedure.from_dict(proc.to_dict())
    secs.append(time.perf_counter() - t0)
    a = pixel_accuracy(rasterize(to_segmentation(proc)), rasterize(flatten(seg)))
    ed = editability(proc, segmentation_lattice(seg))
    acc.append(a), comp.append(compression(proc, seg)), fl.append(ed["floors_plus_one"]), ba.append(ed["bays_plus_one"])
    print(rid, f"unsized {unsized:.3f} sized {a:.3f} comp {comp[-1]:.2f} params {len(proc.parameters())} "
          f"{secs[-1]:.1f}s", flush=True)
print(f"{args.mode}: accuracy {np.mean(acc):.4f} compression {statistics.median(comp):.2f} "
      f"floors+1 {np.mean(fl):.3f} bays+1 {np.mean(ba):.3f} seconds {statistics.median(secs):.2f}")
