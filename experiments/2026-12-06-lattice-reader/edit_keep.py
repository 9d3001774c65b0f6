"""Sizing that keeps how the reading edits: where the sized lattice reading no longer edits as the unsized one does
(`floors` + 1, `bays` + 1 on the procedure itself, no annotation), size again with the exceptions' sizes fixed.

    .venv/bin/python experiments/2026-12-06-lattice-reader/edit_keep.py [--every 1] [--json OUT]
"""
import argparse
import json

from facaid.reading import lattice
from facaid.evaluation.editability import editability, segmentation_lattice
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.grammar.execute import to_segmentation
from facaid.metrics import pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.segmentation import flatten, rasterize
from facaid.sizing import fit_sizes

ap = argparse.ArgumentParser()
ap.add_argument("--every", type=int, default=1)
ap.add_argument("--json")
args = ap.parse_args()


def mask(proc, mode):
    out = []
    for path, node in proc.nodes():
        inside = "!" in path
        out += [inside if mode != "none" else False for _ in node.sizes]
        out += [mode == "all" for o in node.exceptions if o.size is not None]
    return out


def edits(p):
    e = editability(p)
    return e["floors_plus_one"], e["bays_plus_one"]


out = []
for rid, seg in load_records(DEFAULT_CMP, DEV_FACADES)[:: args.every]:
    flat = flatten(seg)
    target = rasterize(flat)
    ann = segmentation_lattice(seg)
    read = lattice.read_lattice(seg)
    if read is None:
        continue
    rec = {"id": rid, "eligible": ann[0] >= 2 and ann[1] >= 2}
    acc = lambda p: pixel_accuracy(rasterize(to_segmentation(p)), target)  # noqa: E731
    e0 = edits(read)
    sized = fit_sizes(read, flat).procedure
    e1 = edits(sized)
    rec.update(unsized=e0, sized=e1, acc_unsized=acc(read), acc_sized=acc(sized),
               truth=editability(sized, ann))
    if e1 != e0 and (e0[0] > e1[0] or e0[1] > e1[1]):
        for mode in ("own", "all"):
            p = fit_sizes(read, flat, fixed=mask(read, mode)).procedure
            rec[mode] = edits(p)
            rec["acc_" + mode] = acc(p)
    out.append(rec)
    print(rid, rec, flush=True)
if args.json:
    json.dump(out, open(args.json, "w"), indent=1)
