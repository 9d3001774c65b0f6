"""Calibrate the annotation noise of training inputs on the CMP dev half (facades 1-189, aggregate statistics only).

    .venv/bin/python experiments/2026-12-03-annotation-calibration/calibrate.py --json calibration.json

How far windows sit off a grid (`facaid.generator.stats.irregularity`) on CMP's dev half, on generated facades, and on
generated facades with uniform edge noise of several widths: the width whose spread matches CMP's, per axis.
"""

import argparse
import json

from facaid.augmentation import annotator_noise
from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.generator.stats import irregularity, load_cmp
from facaid.paths import DEFAULT_CMP


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=300)
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    out = {"cmp_dev": irregularity(load_cmp(DEFAULT_CMP)[:189])}
    generated = [generate(sample_seed(5, i)).segmentation for i in range(args.count)]
    out["generated"] = irregularity(generated)
    for edge in (0.002, 0.003, 0.004, 0.006, 0.008, 0.01):
        noisy = [annotator_noise(seg, i, edge=edge, drop=0.0, spurious=0) for i, seg in enumerate(generated)]
        out[f"generated, edge {edge}"] = irregularity(noisy)
    noisy = [annotator_noise(seg, i, edge=0.006, edge_y=0.003, drop=0.0, spurious=0) for i, seg in enumerate(generated)]
    out["generated, edge 0.006 x, 0.003 y (shipped)"] = irregularity(noisy)
    for name, figures in out.items():
        print(f"{name:<44} " + "  ".join(f"{k} {v:.4f}" for k, v in figures.items()))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
