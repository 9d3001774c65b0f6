"""Write generated facades (default style, seeds 0..N-1) as segmentation lines that `facaid evaluate-real --data`
reads, so that its `--perturb` measures how a reconstruction reads through people's noise where the truth is
known.

    .venv/bin/python experiments/2026-12-03-noise-aware/generated.py --count 40 --out /tmp/generated-40.jsonl
"""

from __future__ import annotations

import argparse
import json

from facaid.generator import generate


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--count", type=int, default=40)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    with open(args.out, "w", encoding="utf-8") as f:
        for seed in range(args.first, args.first + args.count):
            f.write(json.dumps({"id": f"generated{seed}", **generate(seed).segmentation.to_dict()}) + "\n")


if __name__ == "__main__":
    main()
