"""What a tree costs against what it is charged, over the trees the cost model's property test draws (issue 66).

    .venv/bin/python bench/bench_cost_model.py [--examples 300] [--seed 0]

Draws ``--examples`` trees from the strategies of `tests/grammar/test_cost_model.py` (trees of every rule wrapped in
repeats of up to 256 copies with up to 48 exceptions on each of four repeats, and the shape of issue 66's probe at
every size), reads each as the site does (`Procedure.from_json`), and for each tree accepted times what the site
does with it (`walks`: both executors' walks, the first boxes, the C, the named parameters, the CGA). Prints, in
this thread's CPU time: the slowest refusal, the slowest accepted tree's walks, and the most microseconds a unit any
accepted tree took. Targets: refused in ≤ 10 ms, or answered within 1 s of CPU.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path
from time import thread_time

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "grammar")]

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from test_cost_model import drawn, probes, walks  # noqa: E402

from facaid.grammar.layout import count_expansion  # noqa: E402
from facaid.grammar.procedure import Procedure, ProcedureError  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--examples", type=int, default=300)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    refused: list[tuple[float, int]] = []
    accepted: list[tuple[float, int, float]] = []

    @settings(max_examples=args.examples, deadline=None, database=None, derandomize=False,
              suppress_health_check=list(HealthCheck))
    @given(st.one_of(drawn(), probes()))
    def measure(proc: Procedure) -> None:
        text = json.dumps(proc.to_dict())
        start = thread_time()
        try:
            tree = Procedure.from_json(text)
        except ProcedureError:
            refused.append((thread_time() - start, len(text)))
            return
        read = thread_time() - start
        cost = count_expansion(tree.root, tree.width, tree.height).instances
        start = thread_time()
        walks(tree)
        accepted.append((read + thread_time() - start, cost, len(text)))

    import random

    random.seed(args.seed)
    measure()
    worst_refusal = max(refused, default=(0.0, 0))
    worst = max(accepted, default=(0.0, 0, 0))
    per_unit = [1e6 * t / c for t, c, _ in accepted if c >= 1000]
    print(f"{len(refused)} refused: slowest {1000 * worst_refusal[0]:.1f} ms ({worst_refusal[1] / 1024:.0f} KB), "
          f"median {1000 * statistics.median(t for t, _ in refused):.2f} ms" if refused else "none refused")
    print(f"{len(accepted)} accepted: slowest read and walks {worst[0]:.3f} s ({worst[1]:,} units); "
          f"{max(per_unit, default=0):.1f} us a unit at most, {statistics.median(per_unit) if per_unit else 0:.1f} "
          f"median (trees of 1,000 units or more: {len(per_unit)})")


if __name__ == "__main__":
    main()
