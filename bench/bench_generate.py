"""Generator throughput: facades per second, in one process and through `facaid generate` on all cores.

    .venv/bin/python bench/bench_generate.py [--count 20000] [--repeats 3]

Prints the median of the repeats. Target (issue A): >= 1,000 facades/s on 2 cores, files written.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time

from facaid.generator import generate
from facaid.generator.dataset import sample_record, sample_seed, write_dataset
from facaid.grammar import execute
from facaid.grammar.execute import leaf_array
from facaid.segmentation import flatten_array


def per_sample_ms(n: int) -> dict[str, float]:
    """Median cost of each stage for one facade, in milliseconds."""
    from facaid.generator import generate_procedure

    stages: dict[str, list[float]] = {"build+validate": [], "execute": [], "round+flatten": [], "record+json": []}
    for i in range(n):
        seed = sample_seed(99, i)
        t0 = time.perf_counter()
        proc = generate_procedure(seed)
        t1 = time.perf_counter()
        leaves = execute(proc)
        t2 = time.perf_counter()
        flatten_array(round(proc.width), round(proc.height), leaf_array(proc, leaves))
        t3 = time.perf_counter()
        json.dumps(sample_record(99, i))
        t4 = time.perf_counter()
        stages["build+validate"].append(t1 - t0)
        stages["execute"].append(t2 - t1)
        stages["round+flatten"].append(t3 - t2)
        stages["record+json"].append(t4 - t3)
    return {k: 1000 * statistics.median(v) for k, v in stages.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=20000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    generate(0)  # warm imports
    print(f"cores: {os.cpu_count()}")
    for stage, ms in per_sample_ms(500).items():
        print(f"  {stage:<15} {ms:6.3f} ms per facade (median of 500)")
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
