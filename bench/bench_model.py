"""Model speed: training step time with one vs five tokens per rectangle, and inference latency.

    .venv/bin/python bench/bench_model.py [--steps 5] [--facades 30] [--repeat 1] [--k 1] [--checkpoint DIR]

Training steps use the shipped config's model size on the same length-sorted batch of generated facades; the
two input layouts are timed alternately in one run and compared as a ratio (``--steps 0`` skips them).
Inference: greedy, constrained, batch 1, the shipped checkpoint, median over held-out facades (target: <= 300 ms
on 2 CPU cores), with the native C step that `decode` uses (`facaid.native`) and with the torch step, the two
alternating. With ``--repeat R`` each facade is decoded R times in a row; the figures of the first decodes are
printed, and the median of each facade's fastest decode, which leaves out most of what other work on a shared
machine adds (the decodes are the same bit for bit). ``--k K`` times the decoding of best of K instead (the
greedy row and K - 1 samples in one batch, as `facaid.decoding.ranked_candidates` decodes them; ranking and
composition not included): the C step runs the rows in shards on torch's threads.
"""

from __future__ import annotations

import argparse
import statistics
import time

import torch

from facaid.decoding import decode
from facaid.decoding.step import library as native_library
from facaid.defaults import TEMPERATURE
from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.model import FacaidConfig, FacaidModel, batch_inputs, batch_outputs, load_model
from facaid.paths import DEFAULT_CHECKPOINT
from facaid.tokenizer import Tokenizer, TokenizerConfig


def train_step_times(steps: int, batch_size: int = 32) -> dict[int, float]:
    samples = [generate(sample_seed(7, i)) for i in range(batch_size)]
    times: dict[int, list[float]] = {1: [], 5: []}
    setups = {}
    for rt in (1, 5):
        tc = TokenizerConfig(max_rects=1000, max_out=1024, rect_tokens=rt)
        tok = Tokenizer(tc)
        torch.manual_seed(0)
        model = FacaidModel(FacaidConfig(tokenizer=tc.to_dict()))
        rects, mask = batch_inputs([tok.encode_segmentation(s.segmentation) for s in samples])
        ids, local, targets, _ = batch_outputs([tok.encode_procedure(s.procedure) for s in samples])
        setups[rt] = (model, torch.optim.AdamW(model.parameters(), 1e-4), (rects, mask, ids, local, targets))
    for _ in range(steps):
        for rt, (model, opt, batch) in setups.items():
            t0 = time.perf_counter()
            _, loss = model(*batch)
            loss.backward()
            opt.step()
            opt.zero_grad()
            times[rt].append(time.perf_counter() - t0)
    return {rt: statistics.median(v[1:] or v) for rt, v in times.items()}


def inference_latency(checkpoint: str, facades: int, repeat: int = 1, k: int = 1) -> dict[bool, list[list[float]]]:
    """Seconds per decode (greedy, or best of ``k``'s K rows): ``repeat`` decodes of each of ``facades``
    held-out facades, with the native C step (True) and with the torch step (False), the two alternating so
    that both see the same machine."""
    model, tok = load_model(checkpoint)
    seg = generate(sample_seed(999, 0)).segmentation
    rows = {"k": k, "sample": True, "greedy": 1, "temperature": TEMPERATURE} if k > 1 else {}
    for native in (True, False):  # warm-up (builds the native step if needed), not timed (another seed)
        decode(model, tok, seg, native=native, **rows)
    out: dict[bool, list[list[float]]] = {True: [], False: []}
    i = 0
    while len(out[True]) < facades:
        s = generate(sample_seed(1000, i))
        i += 1
        try:
            tok.encode_segmentation(s.segmentation)
        except ValueError:
            continue
        runs: dict[bool, list[float]] = {True: [], False: []}
        for r in range(repeat):
            for native in ((True, False) if (i + r) % 2 else (False, True)):
                t0 = time.perf_counter()
                decode(model, tok, s.segmentation, native=native, seed=i, **rows)
                runs[native].append(time.perf_counter() - t0)
        for native, seconds in runs.items():
            out[native].append(seconds)
    return out


def _figures(seconds: list[float]) -> str:
    return (f"median {1000 * statistics.median(seconds):.0f} ms, "
            f"p90 {1000 * sorted(seconds)[int(0.9 * (len(seconds) - 1))]:.0f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=5)
    parser.add_argument("--facades", type=int, default=30)
    parser.add_argument("--repeat", type=int, default=1, help="decodes of each facade (the fastest is reported too)")
    parser.add_argument("--k", type=int, default=1, help="rows decoded at once: 1 greedy, K > 1 best of K")
    parser.add_argument("--checkpoint", default=str(DEFAULT_CHECKPOINT))
    args = parser.parse_args()
    if args.steps < 0 or args.facades < 0 or args.repeat < 1 or args.k < 1:
        parser.error("--steps and --facades must be at least 0, --repeat and --k at least 1")
    print(f"torch threads: {torch.get_num_threads()}")
    if args.steps:
        t = train_step_times(args.steps)
        print(f"training step, batch 32: 1 token/rect {t[1]:.2f} s, 5 tokens/rect {t[5]:.2f} s "
              f"(5-token / 1-token = {t[5] / t[1]:.2f})")
    if args.facades:
        both = inference_latency(args.checkpoint, args.facades, args.repeat, args.k)
        if native_library() is None:
            print("(no native step on this machine: both rows below run the torch step)")
        for native, name in ((True, "native C step"), (False, "torch step")):
            lat = both[native]
            what = "greedy" if args.k == 1 else f"best of {args.k} (decoding)"
            print(f"inference, {what}, batch 1, {name}, {len(lat)} facades: {_figures([runs[0] for runs in lat])}")
            if args.repeat > 1:
                print(f"  fastest of {args.repeat} decodes per facade: {_figures([min(runs) for runs in lat])}")
        ratios = [min(a) / min(b) for a, b in zip(both[True], both[False], strict=True)]
        print(f"native / torch, median of per-facade ratios: {statistics.median(ratios):.3f}")


if __name__ == "__main__":
    main()
