"""Find copies, left one out: how often a drawn window's copy is proposed where the photo has one and it is not
drawn (issue 68, item 2: it missed an identical window on b0212 and a column on b0287).

    .venv/bin/python experiments/2026-12-07-find-copies/probe.py --photos var/cmp_photos [--stride 3] [--per 6]

For each CMP facade whose photo is in ``--photos`` (a git-ignored cache), up to ``--per`` windows (seeded) are held
out in turn: the annotation less that window and what overlaps it is the drawing, and the unit is the drawn window
of about its size (within 15 % each way) nearest to it. A hit: a proposed window with IoU >= 0.5 with the held-out
one. Prints the hit rate and the misses.
"""
import argparse
import json
from pathlib import Path

import numpy as np
from PIL import Image

from facaid.completion.copies import find_copies
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.labels import LABEL_ID
from facaid.paths import DEFAULT_CMP
from facaid.segmentation import Segmentation

WINDOW, BACKGROUND, FACADE = LABEL_ID["window"], LABEL_ID["background"], LABEL_ID["facade"]


def iou(a, b) -> float:
    ix = max(0, min(a[2], b[2]) - max(a[0], b[0])) * max(0, min(a[3], b[3]) - max(a[1], b[1]))
    u = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - ix
    return ix / u if u else 0.0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--photos", required=True)
    ap.add_argument("--stride", type=int, default=3)
    ap.add_argument("--per", type=int, default=6)
    ap.add_argument("--half", choices=("dev", "test"), default="dev")
    ap.add_argument("--only", default=None, help="comma-separated record ids")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    records = load_records(DEFAULT_CMP)
    records = records[:DEV_FACADES] if args.half == "dev" else records[DEV_FACADES:]
    if args.only:
        keep = set(args.only.split(","))
        records = [r for r in records if r[0] in keep]
    else:
        records = records[:: args.stride]
    hits, tries, misses = 0, 0, []
    for rid, seg in records:
        path = Path(args.photos) / f"{rid}.jpg"
        if not path.exists():
            continue
        photo = Image.open(path).convert("RGB").resize((seg.width, seg.height))
        rows = seg.to_array()
        wins = np.flatnonzero(rows[:, 0] == WINDOW)
        if len(wins) < 3:
            continue
        rng = np.random.default_rng(int(rid[-4:]))
        for t in rng.permutation(wins)[: args.per]:
            box = rows[t, 1:]
            size = np.array([box[2] - box[0], box[3] - box[1]], float)
            overlap = [i for i in range(len(rows)) if i != t and rows[i, 0] not in (BACKGROUND, FACADE)
                       and iou(rows[i, 1:], box) > 0]
            keep = [i for i in range(len(rows)) if i != t and i not in overlap]
            alike = [i for i in keep if rows[i, 0] == WINDOW and np.all(np.abs(
                np.array([rows[i, 3] - rows[i, 1], rows[i, 4] - rows[i, 2]]) / size - 1) <= 0.15)]
            if not alike:
                continue
            centre = (box[:2] + box[2:]) / 2
            unit_old = min(alike, key=lambda i: np.hypot(*((rows[i, 1:3] + rows[i, 3:5]) / 2 - centre)))
            drawn = Segmentation.from_array(seg.width, seg.height, rows[keep])
            unit = keep.index(unit_old)
            found = find_copies(drawn, photo, [unit])
            hit = any(p["label"] == "window" and iou((p["x0"], p["y0"], p["x1"], p["y1"]), box) >= 0.5 for p in found)
            tries += 1
            hits += hit
            if not hit:
                misses.append((rid, [int(v) for v in box], len(found)))
    print(f"{hits} of {tries} held-out windows found ({100 * hits / max(1, tries):.1f} %)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"hits": hits, "tries": tries, "misses": misses}, f)


if __name__ == "__main__":
    main()
