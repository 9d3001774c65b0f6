"""Structure induction (`facaid.reading.induce`) on generated facades, clean and with hand-drawn-like jitter.

    .venv/bin/python bench/bench_induce.py [--count 40] [--sigma 0.004] [--snap 0.01] [--tolerance 0.15]

Held-out generated facades (dataset seed 1100, not the model's training or validation seeds). For each: the
induced procedure's pixel accuracy against its own input before and after sizing, its node count beside the
generator's true procedure and the exact guillotine decomposition (`facaid.grammar.decompose`), and the time
to induce and size it. Jittered inputs move every element edge by N(0, sigma x the longer side) pixels, as
`facaid.augmentation.jitter` does. This is where the defaults of `induce_procedure` were chosen; the CMP
facades are never used for that.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from facaid.augmentation import jitter
from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.grammar.decompose import procedure_from_segmentation
from facaid.metrics import procedure_accuracy
from facaid.reading.induce import induce_procedure
from facaid.segmentation import flatten
from facaid.sizing import fit_sizes


def nodes(proc) -> int:
    return sum(1 for _ in proc.nodes())


def run(count: int, sigma: float, snap: float, tolerance: float) -> None:
    before, after, size, truth, exact, secs = [], [], [], [], [], []
    for i in range(count):
        sample = generate(sample_seed(1100, i))
        seg = sample.segmentation
        if sigma > 0:
            seg = jitter(seg, sigma, np.random.default_rng(i))
        flat = flatten(seg)
        t0 = time.perf_counter()
        proc = induce_procedure(flat, snap=snap, tolerance=tolerance)
        fitted = fit_sizes(proc, flat)
        secs.append(time.perf_counter() - t0)
        before.append(procedure_accuracy(proc, flat))
        after.append(fitted.accuracy)
        size.append(nodes(proc))
        truth.append(nodes(sample.procedure))
        exact.append(nodes(procedure_from_segmentation(flat)))
    a = np.array(after)
    print(f"sigma {sigma:g} (snap {snap:g}, tolerance {tolerance:g}), {count} facades: pixel accuracy median "
          f"{100 * np.median(before):.2f} % induced, {100 * np.median(a):.2f} % sized (mean {100 * a.mean():.2f} %, "
          f">= 95 %: {100 * (a >= 0.95).mean():.1f} % of facades); nodes median {statistics.median(size):.0f} "
          f"(true procedure {statistics.median(truth):.0f}, exact decomposition {statistics.median(exact):.0f}); "
          f"induce + size median {1000 * statistics.median(secs):.0f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=40)
    parser.add_argument("--sigma", type=float, default=0.004, help="jitter of the noisy run (0: clean only)")
    parser.add_argument("--snap", type=float, default=0.01)
    parser.add_argument("--tolerance", type=float, default=0.15)
    args = parser.parse_args()
    run(args.count, 0.0, args.snap, args.tolerance)
    if args.sigma > 0:
        run(args.count, args.sigma, args.snap, args.tolerance)


if __name__ == "__main__":
    main()
