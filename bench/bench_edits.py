"""Edits of generated facades judged as a person looks (issue 67's generated target: `floors` + 1 and `bays` + 1
both clean on at least 95 % of the facades).

    .venv/bin/python bench/bench_edits.py [--start 5000] [--count 100]

Held-out generated facades (seeds ``--start`` on; the training data is drawn from other seeds), those with a lattice
of windows (two rows and two columns at least, as on CMP: `facaid.reading.windows.lattice`). Each is edited by its
named parameters and judged by `facaid.editing.check` (no annotation: before against after). Prints the share with
both edits clean, the reasons of the others, and their seeds.
"""

from __future__ import annotations

import argparse
from collections import Counter

from facaid.evaluation.editability import generated_edits


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--start", type=int, default=5000)
    ap.add_argument("--count", type=int, default=100)
    args = ap.parse_args()
    eligible, clean, others = generated_edits(range(args.start, args.start + args.count))
    both, failed = len(clean), sorted(others)
    why: Counter = Counter()
    for verdicts in others.values():
        for key, v in verdicts.items():
            if v is None or not v.clean:
                why[(key.replace("+1", " + 1"), "no such edit" if v is None else v.reason.split(" (")[0])] += 1
    print(f"seeds {args.start}-{args.start + args.count - 1}: {eligible} with a lattice of windows; floors + 1 and "
          f"bays + 1 both clean on {both} ({100 * both / max(1, eligible):.1f} %; target 95 %)")
    for (edit, reason), n in why.most_common():
        if n:
            print(f"  {n} {edit}: {reason}")
    print(f"  not clean: {failed}")


if __name__ == "__main__":
    main()
