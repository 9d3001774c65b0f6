"""Where the lattice reader's element leaves sit (what compression pays for), on CMP dev facades, unsized.

    .venv/bin/python experiments/2026-12-06-lattice-reader/breakdown.py [--every 9]
"""
import argparse
import collections
import statistics

from facaid.reading import lattice
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.metrics import element_rectangles
from facaid.paths import DEFAULT_CMP

ap = argparse.ArgumentParser()
ap.add_argument("--every", type=int, default=9)
ap.add_argument("--start", type=int, default=0)
args = ap.parse_args()
totals = collections.Counter()
comps = []
for rid, seg in load_records(DEFAULT_CMP, DEV_FACADES)[args.start :: args.every]:
    proc = lattice.read_lattice(seg)
    if proc is None:
        continue
    nodes = dict(proc.root.walk())
    count = collections.Counter()
    for path, node in nodes.items():
        if node.rule != "leaf" or node.label in ("facade", "background"):
            continue
        parts = path.split("/")
        band = nodes["/".join(parts[:2])].role if len(parts) > 1 else "?"
        kind = "typical"
        for k, p in enumerate(parts):
            if p.startswith("!"):
                owner = nodes["/".join(parts[:k])]
                exc = owner.exceptions[int(p[1:])]
                what = "column" if owner.role == "bay" and band == "floors" else (
                    "row" if exc.node.role == "bay" else ("relabel" if exc.node.rule == "leaf" else "own"))
                kind = f"{what}"
                break
        count[f"{band}:{kind}"] += 1
    n = element_rectangles(seg)
    comps.append(n / max(1, sum(count.values())))
    totals.update(count)
    print(rid, n, dict(count), flush=True)
print("compression median", statistics.median(comps))
s = sum(totals.values())
for k, v in totals.most_common():
    print(f"{k:24s} {v:5d} {100 * v / s:5.1f} %")
