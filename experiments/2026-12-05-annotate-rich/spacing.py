"""How irregular the floors' and bays' spacing is: per facade, the window rows' (columns') centres of the flattened
footprint form (rows of at least 3 windows), their consecutive pitches, and the median absolute deviation of
those pitches from their median as a share of the median pitch; medians over facades. The CMP dev half (aggregate
statistics only) against generated facades, plain and with `spacing` noise.

    .venv/bin/python experiments/2026-12-05-annotate-rich/spacing.py --count 189 --spacing 0.0125,0.022 0.0125,0.025
"""

from __future__ import annotations

import argparse

import numpy as np

from facaid.augmentation import annotator_noise
from facaid.evaluation.real import load_records
from facaid.generator import generate
from facaid.generator.stats import WINDOW
from facaid.paths import DEFAULT_CMP
from facaid.segmentation import aligned_lines, flatten


def pitch_spread(seg) -> tuple[float | None, float | None]:
    rows = flatten(seg, wall="footprint").to_array()
    win = rows[rows[:, 0] == WINDOW].astype(float)
    out = []
    for lo_col, hi_col in ((2, 4), (1, 3)):
        lo, hi = win[:, lo_col], win[:, hi_col]
        centres = sorted(float(np.median((lo[m] + hi[m]) / 2)) for m in aligned_lines(lo, hi) if len(m) >= 3)
        p = np.diff(centres)
        if len(p) < 2:
            out.append(None)
            continue
        med = np.median(p)
        out.append(float(np.median(np.abs(p - med)) / med))
    return out[0], out[1]


def summary(name: str, segs) -> None:
    ys, xs = zip(*(pitch_spread(s) for s in segs), strict=True)
    ys, xs = [v for v in ys if v is not None], [v for v in xs if v is not None]
    print(f"{name}: floors {np.median(ys):.4f} (mean {np.mean(ys):.4f}, {len(ys)} facades); "
          f"bays {np.median(xs):.4f} (mean {np.mean(xs):.4f}, {len(xs)} facades)")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--count", type=int, default=189)
    ap.add_argument("--spacing", nargs="*", default=["0.0125,0.022"], help="pairs x,y: 0.01,0.02")
    args = ap.parse_args()
    summary("CMP dev", [s for _, s in load_records(DEFAULT_CMP, min(args.count, 189))])
    gen = [generate(seed).segmentation for seed in range(args.count)]
    summary("generated", gen)
    for pair in args.spacing:
        sx, sy = (float(v) for v in pair.split(",")) if "," in pair else (float(pair),) * 2
        summary(f"generated, spacing x {sx} y {sy}", [annotator_noise(s, i, edge=0.0, drop=0.0, spurious=0, spacing=sx,
                                                                      spacing_y=sy) for i, s in enumerate(gen)])


if __name__ == "__main__":
    main()
