"""How well the proposed corners find the facade in a photo (issue 57's corners target).

    .venv/bin/python bench/bench_corners.py --photos var/cmp_photos [--limit N] [--warp SEED] [--json F]
    .venv/bin/python bench/bench_corners.py --photos var/cmp_photos_test --half test   # once, for a closing note

For each CMP dev-half photo in ``--photos`` (``cmp_bNNNN.jpg``, the git-ignored cache of the public copy of CMP's
base set; CMP's photos are rectified facades), `facaid.photo.corners.propose_corners_file` proposes the facade's four
corners; the figure is the IoU of that quadrilateral with the annotation's facade box (the bounding box of its
wall rectangles), counted over the pixels that hold data: the facade as the photo shows it, for the box takes in
the no-data wedges an earlier rectification left at the photo's corners, which the proposal leaves out
(`facaid.photo.nodata`). ``--all-pixels`` counts every pixel, as issue 57 did. ``--warp SEED`` first warps each
photo by a random perspective of its own (the corners moved inwards by up to a fifth of the side, seeded), so the
known corners are the warped facade box's, and scores the proposal against them. Target: IoU ≥ 0.85 on ≥ 80 % of
the dev-half photos. Also prints how many proposals hold no data (none should: issue 68), and where a wedge cuts
into the facade and the proposal offers the whole facade beside (``"whole"``), the share reached when the person
takes that where it does better.
"""

from __future__ import annotations

import argparse
import io
import json
import statistics
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.labels import FACADE
from facaid.paths import DEFAULT_CMP
from facaid.photo.corners import propose_corners_file
from facaid.photo.nodata import held, nodata_mask
from facaid.photo.rectify import homography


def facade_box(seg) -> tuple[int, int, int, int] | None:
    walls = [r for r in seg.rects if r.label == FACADE]
    if not walls:
        return None
    return (min(r.x0 for r in walls), min(r.y0 for r in walls), max(r.x1 for r in walls), max(r.y1 for r in walls))


def quad_iou(a, b, size: tuple[int, int], scale: float = 0.25, data: np.ndarray | None = None) -> float:
    """IoU of two quadrilaterals ([[x, y] x 4]) drawn on a grid of ``size`` x ``scale``; with ``data`` (a mask of
    that grid), over its pixels only."""
    w, h = max(1, round(size[0] * scale)), max(1, round(size[1] * scale))
    masks = []
    for quad in (a, b):
        img = Image.new("1", (w, h))
        ImageDraw.Draw(img).polygon([(x * scale, y * scale) for x, y in quad], fill=1)
        masks.append(np.asarray(img, dtype=bool) & (data if data is not None else True))
    union = (masks[0] | masks[1]).sum()
    return float((masks[0] & masks[1]).sum() / union) if union else 0.0


def nodata_held(quad, data: np.ndarray, scale: float = 0.25) -> float:
    """The share of the quadrilateral ``quad`` (on `quad_iou`'s grid of ``data``) that holds no data: what the
    proposal itself measures (`facaid.photo.nodata.held`)."""
    return held(np.asarray(quad, dtype=float) * scale, ~data)


def data_pixels(photo: Image.Image, scale: float = 0.25) -> np.ndarray:
    """The pixels of ``photo`` (on `quad_iou`'s grid) that hold data: all but its no-data wedges."""
    w, h = max(1, round(photo.width * scale)), max(1, round(photo.height * scale))
    return ~nodata_mask(np.asarray(photo.convert("L").resize((w, h), Image.Resampling.NEAREST)))


def warped(photo: Image.Image, box, rng: np.random.Generator) -> tuple[Image.Image, list[list[float]]]:
    """The photo seen in a random perspective, and where its facade box's corners went."""
    w, h = photo.size
    src = np.array([[0, 0], [w, 0], [w, h], [0, h]], dtype=float)
    dst = src + rng.uniform(0, 0.2, size=(4, 2)) * np.array([[w, h], [-w, h], [-w, -h], [w, -h]])
    m = homography(src, dst)  # photo -> warped
    inverse = np.linalg.inv(m)
    out = photo.transform((w, h), Image.Transform.PERSPECTIVE, (inverse / inverse[2, 2]).ravel()[:8].tolist(),
                          Image.Resampling.BILINEAR)
    x0, y0, x1, y1 = box
    corners = np.array([[x0, y0, 1], [x1, y0, 1], [x1, y1, 1], [x0, y1, 1]], dtype=float) @ m.T
    return out, (corners[:, :2] / corners[:, 2:]).tolist()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--photos", required=True)
    ap.add_argument("--data", default=str(DEFAULT_CMP))
    ap.add_argument("--limit", type=int, default=DEV_FACADES)
    ap.add_argument("--half", choices=("dev", "test"), default="dev",
                    help="the dev half (1-189, for tuning) or the test half (190-378, reported once)")
    ap.add_argument("--warp", type=int, default=None, help="warp each photo by a seeded random perspective first")
    ap.add_argument("--all-pixels", action="store_true", help="count the no-data wedges' pixels too (issue 57)")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    rows = []
    records = load_records(args.data)
    half = records[:DEV_FACADES] if args.half == "dev" else records[DEV_FACADES:]
    for k, (rid, seg) in enumerate(half[: args.limit]):
        path = Path(args.photos) / f"{rid}.jpg"
        box = facade_box(seg)
        if not path.exists() or box is None:
            continue
        photo = Image.open(path).convert("RGB")
        if photo.size != (seg.width, seg.height):
            photo = photo.resize((seg.width, seg.height))
        truth = [[box[0], box[1]], [box[2], box[1]], [box[2], box[3]], [box[0], box[3]]]
        if args.warp is not None:
            photo, truth = warped(photo, box, np.random.default_rng([args.warp, k]))
        buf = io.BytesIO()
        photo.save(buf, "JPEG", quality=92)
        buf.seek(0)
        found = propose_corners_file(buf)
        data = data_pixels(photo)
        share = nodata_held(found["corners"], data)
        data = None if args.all_pixels else data
        rows.append({"id": rid, "iou": quad_iou(found["corners"], truth, photo.size, data=data),
                     "iou_all": quad_iou(found["corners"], truth, photo.size),
                     "held": share,
                     "corners": found["corners"], "truth": truth, "confidence": found["confidence"],
                     "notes": found["notes"]})
        if "whole" in found:  # a wedge cuts into the facade: the person's one click ("Take in the wedge")
            rows[-1]["whole_iou"] = quad_iou(found["whole"], truth, photo.size, data=data)
    ious = [r["iou"] for r in rows]
    good = sum(i >= 0.85 for i in ious)
    over = "every pixel" if args.all_pixels else "the pixels with data"
    print(f"{len(rows)} photos{' (warped)' if args.warp is not None else ''}: IoU with the facade box over {over} "
          f"median {statistics.median(ious):.3f}, ≥ 0.85 on {good} ({100 * good / len(rows):.0f} %; target 80 %); "
          f"{sum(r['held'] > 0.005 for r in rows)} proposals hold over 0.5 % no data")
    offered = [r for r in rows if "whole_iou" in r]
    taken = sum(max(r["iou"], r.get("whole_iou", 0.0)) >= 0.85 for r in rows)
    print(f"a wedge cut into the facade on {len(offered)}: with \"Take in the wedge\" where it does better, ≥ 0.85 on "
          f"{taken} ({100 * taken / max(1, len(rows)):.0f} %)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
