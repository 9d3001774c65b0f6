"""Shared sizes that no pixel depends on (every copy that uses them overrides them), set to the median of the
copies' own values after the sizing: does it mend floors + 1 and bays + 1? Reads the sized readings that
`failures.py` cached.

    .venv/bin/python experiments/2026-12-07-copy-geometry/unused.py [--cache DIR]
"""
import argparse
import glob
import json
import os

import numpy as np

from facaid.evaluation.editability import flat_rows, lattice as rows_cols
from facaid.grammar.execute import to_segmentation
from facaid.grammar.procedure import Procedure, Size
from facaid.grammar.repeats import along_path
from facaid.editing.parameters import named_parameters, set_parameter
from facaid.segmentation import rasterize

ap = argparse.ArgumentParser()
ap.add_argument("--cache", default="/tmp/w/procs")
args = ap.parse_args()


def edits(proc):
    names = {p.name: p for p in named_parameters(proc)}
    before = rows_cols(flat_rows(proc))
    out = []
    for name, grows in (("floors", 0), ("bays", 1)):
        after = rows_cols(flat_rows(set_parameter(proc, name, names[name].value + 1)))
        out.append(after[grows] == before[grows] + 1 and after[1 - grows] == before[1 - grows])
    return out


def unused_sizes(proc):
    """(id of node, size index) of the node sizes (not exceptions') whose change changes no pixel."""
    base = rasterize(to_segmentation(proc))
    values = proc.parameters()
    keys, k = [], 0
    for _, node in proc.root.walk():
        for i, _ in enumerate(node.sizes):
            keys.append((k, id(node), i))
            k += 1
        k += sum(1 for o in node.exceptions if o.size is not None)
    out = set()
    for k, nid, i in keys:
        v = list(values)
        v[k] = v[k] * 1.2 + 4
        try:
            if np.array_equal(rasterize(to_segmentation(proc.with_parameters(v))), base):
                out.add((nid, i))
        except Exception:
            pass
    return out


def settle_unused(proc):
    unused = unused_sizes(proc)
    nodes_by_id = {id(n): n for _, n in proc.root.walk()}
    changed = 0
    for _, rep in proc.root.walk():
        if rep.rule != "repeat" or not rep.exceptions:
            continue
        groups = {}
        for o in rep.exceptions:
            if o.size is None or o.node is not None or len(o.path) < 2:
                continue
            parent = None
            for s, target in along_path(rep, o, rep.exceptions):
                if s == len(o.path) - 2:
                    parent = target
            if parent is None or parent.rule != "split" or (id(parent), o.path[-1]) not in unused:
                continue
            groups.setdefault((id(parent), o.path[-1]), []).append(o.size)
        for (nid, i), sizes in groups.items():
            node = nodes_by_id[nid]
            if all(s.mode == node.sizes[i].mode for s in sizes):
                node.sizes[i] = Size(node.sizes[i].mode, float(np.median([s.value for s in sizes])))
                changed += 1
    return changed


tot = np.zeros(4)
n = 0
for path in sorted(glob.glob(f"{args.cache}/*.json")):
    proc = Procedure.from_dict(json.load(open(path)))
    a = edits(proc)
    before = rasterize(to_segmentation(proc))
    changed = settle_unused(proc)
    proc = Procedure.from_dict(proc.to_dict())
    same = np.array_equal(before, rasterize(to_segmentation(proc)))
    b = edits(proc)
    tot += np.array(a + b)
    n += 1
    print(os.path.basename(path)[:-5], "changed", changed, "same render", same, "before", a, "after", b, flush=True)
print(f"{n} facades: floors+1 {tot[0] / n:.3f} -> {tot[2] / n:.3f}, bays+1 {tot[1] / n:.3f} -> {tot[3] / n:.3f}")
