"""Which part of annotator noise the lattice reader restores, on every 9th CMP dev facade, sized as the pipeline does.

    .venv/bin/python experiments/2026-12-06-lattice-reader/noise.py KIND [--snap SHARE] [--oracle]

KIND: clean, edge (edges moved only), drop (elements left out only), spur (spurious boxes only) or all
(`facaid.augmentation.annotator_noise` as `evaluate-real --perturb` draws it). ``--snap``: the input's edges snapped
first (`snap.py`); ``--oracle``: the structure read from the clean annotation, sized on the noisy one.
"""
import argparse
import sys

import numpy as np

sys.path.insert(0, "experiments/2026-12-06-lattice-reader")
from snap import snap  # noqa: E402

from facaid.reading import lattice  # noqa: E402
from facaid.augmentation import annotator_noise  # noqa: E402
from facaid.evaluation.real import DEV_FACADES, load_records  # noqa: E402
from facaid.grammar.execute import to_segmentation  # noqa: E402
from facaid.metrics import pixel_accuracy  # noqa: E402
from facaid.paths import DEFAULT_CMP  # noqa: E402
from facaid.segmentation import flatten, rasterize  # noqa: E402
from facaid.sizing import fit_sizes  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("kind", choices=["clean", "edge", "drop", "spur", "all"])
ap.add_argument("--snap", type=float, default=0.0)
ap.add_argument("--oracle", action="store_true")
args = ap.parse_args()
kw = {"edge": dict(drop=0, spurious=0), "drop": dict(edge=0, spurious=0), "spur": dict(edge=0, drop=0), "all": {},
      "clean": dict(edge=0, drop=0, spurious=0)}[args.kind]
given_acc, snapped_acc, read_acc = [], [], []
for k, (rid, seg) in enumerate(load_records(DEFAULT_CMP, DEV_FACADES)[0::9]):
    target = rasterize(flatten(seg))
    given = annotator_noise(seg, 100_003 + k, **kw)
    snapped = snap(given, args.snap) if args.snap > 0 else given
    proc = lattice.read_lattice(seg if args.oracle else snapped)
    proc = fit_sizes(proc, flatten(snapped), polish_steps=160).procedure
    given_acc.append(pixel_accuracy(rasterize(flatten(given)), target))
    snapped_acc.append(pixel_accuracy(rasterize(flatten(snapped)), target))
    read_acc.append(pixel_accuracy(rasterize(to_segmentation(proc)), target))
print(f"{args.kind} snap {args.snap} oracle {args.oracle}: input {np.mean(given_acc):.4f} snapped "
      f"{np.mean(snapped_acc):.4f} reader {np.mean(read_acc):.4f} "
      f"({100 * (np.mean(read_acc) - np.mean(given_acc)):+.2f} points)")
