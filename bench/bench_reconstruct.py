"""Reconstruction: sizing accuracy and time, and the whole pipeline with the shipped model.

    .venv/bin/python bench/bench_reconstruct.py [--count 100] [--k K] [--checkpoint DIR] [--no-model]
    .venv/bin/python bench/bench_reconstruct.py --real 40 [--k K]

Held-out generated facades (dataset seed 1000). Sizing alone starts from the true structure with sizes
quantized by the tokenizer (what a perfect decoder would give); the pipeline runs `facaid.reconstruct` (the
model, and the induced structure where the model's fits below 97 %), with the median time of its stages.
Targets (issue C): median pixel accuracy >= 99 %, >= 95 % of facades >= 95 %, median <= 1 s on 2 CPU cores.

``--real N`` times the whole `facaid.reconstruct` instead on the first N CMP dev facades (evaluation only), both
procedures (the exact one and the lattice reading with its edits checked), with the median time of each stage.
Target (issue 67): <= 2 s median on 2 cores.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from facaid.defaults import DEFAULT_K
from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.paths import DEFAULT_CHECKPOINT
from facaid.sizing import fit_sizes
from facaid.tokenizer import Tokenizer, TokenizerConfig


def report(name: str, acc: list[float], secs: list[float]) -> None:
    a = np.array(acc)
    print(f"{name}: {len(a)} facades, pixel accuracy median {100 * np.median(a):.2f} %, mean {100 * a.mean():.2f} %, "
          f">= 95 %: {100 * (a >= 0.95).mean():.1f} % of facades; time median {1000 * statistics.median(secs):.0f} ms, "
          f"p90 {1000 * float(np.percentile(secs, 90)):.0f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=100)
    parser.add_argument("--k", type=int, default=DEFAULT_K)
    parser.add_argument("--checkpoint", default=str(DEFAULT_CHECKPOINT))
    parser.add_argument("--no-model", action="store_true")
    parser.add_argument("--real", type=int, default=0, help="time N CMP dev facades instead")
    args = parser.parse_args()
    if args.real:
        return real(args)
    samples = [generate(sample_seed(1000, i)) for i in range(args.count)]

    tok = Tokenizer(TokenizerConfig(max_rects=5000, max_out=5000))
    acc, secs, before = [], [], []
    for s in samples:
        q = tok.decode_procedure(tok.encode_procedure(s.procedure)[0], s.procedure.width, s.procedure.height)
        t0 = time.perf_counter()
        r = fit_sizes(q, s.segmentation)
        secs.append(time.perf_counter() - t0)
        acc.append(r.accuracy)
        before.append(r.accuracy_before)
    print(f"quantized sizes before sizing: median {100 * np.median(before):.2f} %")
    report("sizing from quantized sizes", acc, secs)

    if args.no_model:
        return
    from facaid.model import load_model
    from facaid.pipeline import ReconstructOptions, reconstruct

    model, tokenizer = load_model(args.checkpoint)
    acc, secs, decoded, retried, induced, shortcut, stages = [], [], [], [], [], [], []
    for s in samples:
        t0 = time.perf_counter()
        try:
            r = reconstruct(s.segmentation, ReconstructOptions(k=args.k), model=model, tokenizer=tokenizer)
        except ValueError:
            continue
        secs.append(time.perf_counter() - t0)
        acc.append(r.accuracy)
        decoded.append(r.accuracy_decoded)
        retried.append(r.retried)
        induced.append(r.source == "induced")
        shortcut.append(r.shortcut)
        stages.append(r.timings)
    print(f"decoded (best of {args.k}) before sizing: median {100 * np.median(decoded):.2f} %; induced structure "
          f"kept for {100 * np.mean(induced):.1f} % (alone: {100 * np.mean(shortcut):.1f} %), "
          f"second chance sampled for {100 * np.mean(retried):.1f} % of facades")
    report(f"facaid.reconstruct, best of {args.k}", acc, secs)
    print("  stages, median: " + ", ".join(f"{name} {1000 * statistics.median(t[name] for t in stages):.0f} ms"
                                           for name in ("flatten", "decode", "sizing")))


def real(args: argparse.Namespace) -> None:
    from facaid.evaluation.real import load_records
    from facaid.model import load_model
    from facaid.paths import DEFAULT_CMP
    from facaid.pipeline import ReconstructOptions, reconstruct

    model, tokenizer = load_model(args.checkpoint)
    records = load_records(DEFAULT_CMP, min(args.real, 189))  # the dev half
    secs, stages, decoded = [], [], []
    for _, seg in records:
        t0 = time.perf_counter()
        r = reconstruct(seg, ReconstructOptions(k=args.k), model=model, tokenizer=tokenizer)
        secs.append(time.perf_counter() - t0)
        stages.append(r.timings)
        decoded.append(r.candidates)
    print(f"facaid.reconstruct on {len(secs)} CMP dev facades, best of {args.k}, both procedures: "
          f"median {statistics.median(secs):.3f} s, p90 {float(np.percentile(secs, 90)):.3f} s; "
          f"{statistics.median(decoded):.0f} candidates decoded (median)")
    print("  stages, median: " + ", ".join(f"{name} {1000 * statistics.median(t[name] for t in stages):.0f} ms"
                                           for name in ("flatten", "decode", "sizing", "lattice")))


if __name__ == "__main__":
    main()
