"""Generator throughput: facades per second, in one process and through `facaid generate` on all cores.

    .venv/bin/python bench/bench_generate.py [--count 20000] [--repeats 3]

Prints the median of the repeats. Target: >= 1,000 facades/s on 2 cores, files written (issues A and J).
``FACAID_NATIVE=0`` measures the pure-Python path.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

from facaid.generator import generate, generate_rows
from facaid.generator.dataset import sample_line, sample_seed, write_dataset
from facaid.grammar.execute import flat_rows
from facaid.native.rects import library


def per_sample_ms(n: int) -> dict[str, float]:
    """Median cost of each stage for one facade, in milliseconds: the procedure built (styles, H_p, H_a, scaled to
    pixels, `canonical`), executed and flattened to its segmentation's rows (`flat_rows`, in C where it builds),
    and the whole record written as its JSON line (`sample_line`, which does both again)."""
    stages: dict[str, list[float]] = {"build": [], "execute+flatten": [], "record line": []}
    for i in range(n):
        seed = sample_seed(99, i)
        t0 = time.perf_counter()
        proc, _ = generate_rows(seed)
        t1 = time.perf_counter()
        flat_rows(proc)
        t2 = time.perf_counter()
        sample_line(99, i)
        t3 = time.perf_counter()
        stages["execute+flatten"].append(t2 - t1)
        stages["build"].append((t1 - t0) - (t2 - t1))
        stages["record line"].append(t3 - t2)
    return {k: 1000 * statistics.median(v) for k, v in stages.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=20000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    generate(0)  # warm imports
    print(f"cores: {os.cpu_count()}; native rectangles library: {'yes' if library() else 'no (numpy path)'}")
    for stage, ms in per_sample_ms(500).items():
        print(f"  {stage:<16} {ms:6.3f} ms per facade (median of 500)")
    rates = []
    for _ in range(args.repeats):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            write_dataset(tmp, args.count, seed=1, shard_size=1000, progress=False)
            rates.append(args.count / (time.perf_counter() - t0))
    print(f"facaid generate, {args.count} facades, all cores: median {statistics.median(rates):.0f} facades/s "
          f"(runs: {', '.join(f'{r:.0f}' for r in rates)})")


if __name__ == "__main__":
    main()
