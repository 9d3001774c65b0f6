"""Where floors + 1 and bays + 1 fail on the shipped reading, sized: rows and columns before and after.

    .venv/bin/python experiments/2026-12-07-copy-geometry/failures.py [--every 1] [--cache DIR]
"""
import argparse
import json
import os

from facaid.reading import lattice
from facaid.evaluation.editability import flat_rows, lattice as rows_cols
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.grammar.procedure import Procedure
from facaid.editing.parameters import named_parameters, set_parameter
from facaid.paths import DEFAULT_CMP
from facaid.segmentation import flatten
from facaid.sizing import fit_sizes

ap = argparse.ArgumentParser()
ap.add_argument("--every", type=int, default=1)
ap.add_argument("--cache", default="/tmp/w/procs")
args = ap.parse_args()
os.makedirs(args.cache, exist_ok=True)
for rid, seg in load_records(DEFAULT_CMP, DEV_FACADES)[:: args.every]:
    path = f"{args.cache}/{rid}.json"
    if os.path.exists(path):
        proc = Procedure.from_dict(json.load(open(path)))
    else:
        proc = lattice.read_lattice(seg)
        if proc is None:
            continue
        proc = fit_sizes(proc, flatten(seg), polish_steps=160).procedure
        json.dump(proc.to_dict(), open(path, "w"))
    names = {p.name: p for p in named_parameters(proc)}
    before = rows_cols(flat_rows(proc))
    line = []
    for name in ("floors", "bays"):
        p = names[name]
        after = rows_cols(flat_rows(set_parameter(proc, name, p.value + 1)))
        ok = after[0] == before[0] + (name == "floors") and after[1] == before[1] + (name == "bays")
        line.append(f"{name}:{'ok' if ok else 'FAIL'} {before}->{after}")
    print(rid, *line, flush=True)
