"""Find the copies of one drawn window in a CMP dev photo: methods compared (issue 57).

    .venv/bin/python experiments/2026-12-06-copies/proto.py --every 3 [--method lattice]
"""
import argparse
import statistics
import time

import cv2
import numpy as np

from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.paths import DEFAULT_CMP
from facaid.photo import appearance

ap = argparse.ArgumentParser()
ap.add_argument("--every", type=int, default=3)
ap.add_argument("--limit", type=int, default=DEV_FACADES)
ap.add_argument("--method", default="all")
ap.add_argument("--photos", default="var/cmp_photos")
ap.add_argument("--thr_axis", type=float, default=0.35)
ap.add_argument("--thr_cell", type=float, default=0.45)
ap.add_argument("--set", nargs="*", default=[], help="facaid.completion.copies knobs, NAME=VALUE (Python literal)")
args = ap.parse_args()
import ast
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import lattice_copies as _copies  # noqa: E402  (the lattice per type, not landed)

for kv in args.set:
    k, v = kv.split("=", 1)
    setattr(_copies, k, ast.literal_eval(v))


def iou(a, b):
    ix = np.maximum(0, np.minimum(a[2], b[:, 2]) - np.maximum(a[0], b[:, 0]))
    iy = np.maximum(0, np.minimum(a[3], b[:, 3]) - np.maximum(a[1], b[:, 1]))
    inter = ix * iy
    return inter / ((a[2] - a[0]) * (a[3] - a[1]) + (b[:, 2] - b[:, 0]) * (b[:, 3] - b[:, 1]) - inter)


def pick_unit(wins):
    """The drawn one: the window nearest the median size, first in reading order among the nearest third."""
    w, h = wins[:, 2] - wins[:, 0], wins[:, 3] - wins[:, 1]
    d = np.abs(np.log(w / np.median(w))) + np.abs(np.log(h / np.median(h)))
    near = np.argsort(d)[: max(1, len(d) // 3)]
    return int(min(near, key=lambda i: (wins[i, 1], wins[i, 0])))


def normalised(grey, s):
    g = grey.astype(np.float32)
    m = cv2.GaussianBlur(g, (0, 0), s)
    d = g - m
    v = cv2.GaussianBlur(d * d, (0, 0), s)
    return d / np.sqrt(v + 25.0)


def method_ncc(grey, unit, wins_drawn):
    lv = appearance.Levels(grey.astype(np.float32))
    w, h = unit[2] - unit[0], unit[3] - unit[1]
    boxes, sims = appearance.search(lv, unit[None], (w, h), 0.93)
    return boxes, sims


def response_map(img, unit, ctx=0.25):
    w, h = unit[2] - unit[0], unit[3] - unit[1]
    mx, my = round(ctx * w), round(ctx * h)
    x0, y0, x1, y1 = (int(round(v)) for v in unit)
    H, W = img.shape
    a, b, c, d = max(0, x0 - mx), max(0, y0 - my), min(W, x1 + mx), min(H, y1 + my)
    t = img[b:d, a:c]
    r = cv2.matchTemplate(img, t, cv2.TM_CCOEFF_NORMED)
    return r, (x0 - a, y0 - b)  # r[y, x]: the template's top-left at (x, y); offset of the unit inside it


def peaks1d(p, sep, thr):
    out = []
    order = np.argsort(-p)
    taken = np.zeros(len(p), bool)
    for i in order:
        if p[i] < thr:
            break
        if taken[max(0, i - sep): i + sep + 1].any():
            continue
        taken[i] = True
        out.append(int(i))
    return sorted(out)


def method_lattice(grey, unit, wins_drawn, *, norm=True, thr_axis=None, thr_cell=None, size=True):
    thr_axis = args.thr_axis if thr_axis is None else thr_axis
    thr_cell = args.thr_cell if thr_cell is None else thr_cell
    w, h = unit[2] - unit[0], unit[3] - unit[1]
    img = normalised(grey, max(w, h)) if norm else grey.astype(np.float32)
    r, (ox, oy) = response_map(img, unit)
    rh, rw = r.shape
    ux, uy = int(round(unit[0])) - ox, int(round(unit[1])) - oy  # the unit's own place in r
    dy, dx = max(1, round(0.1 * h)), max(1, round(0.1 * w))
    row = r[max(0, uy - dy): uy + dy + 1].max(axis=0)
    col = r[:, max(0, ux - dx): ux + dx + 1].max(axis=1)
    xs = peaks1d(row, max(1, int(0.7 * w)), thr_axis)
    ys = peaks1d(col, max(1, int(0.7 * h)), thr_axis)
    out, sims = [], []
    for y in ys:
        for x in xs:
            a, b = max(0, y - dy), max(0, x - dx)
            win = r[a: y + dy + 1, b: x + dx + 1]
            k = np.unravel_index(int(win.argmax()), win.shape)
            s = float(win[k])
            if s < thr_cell:
                continue
            px, py = b + k[1] + ox, a + k[0] + oy
            out.append([px, py, px + w, py + h])
            sims.append(s)
    boxes = np.array(out, float).reshape(-1, 4)
    if size == "bands" and len(boxes):
        boxes = band_snap(grey, boxes, unit)
    elif size and len(boxes):
        boxes = snap(grey, boxes)
    return boxes, np.array(sims)


def _groups(lo, size):
    """Indices grouped by position: lo values within 0.3 size of a group's first."""
    order = np.argsort(lo)
    groups, cur = [], [order[0]]
    for i in order[1:]:
        if lo[i] - lo[cur[0]] <= 0.3 * size:
            cur.append(i)
        else:
            groups.append(cur)
            cur = [i]
    groups.append(cur)
    return groups


def band_snap(grey, boxes, unit, reach=0.25):
    g = cv2.GaussianBlur(grey.astype(np.float32), (0, 0), 1.0)
    grad = {1: np.abs(cv2.Sobel(g, cv2.CV_32F, 0, 1)), 0: np.abs(cv2.Sobel(g, cv2.CV_32F, 1, 0))}
    H, W = g.shape
    w, h = unit[2] - unit[0], unit[3] - unit[1]
    out = boxes.copy()
    for axis, (a, b), size, cross in ((1, (1, 3), h, (0, 2)), (0, (0, 2), w, (1, 3))):
        r = max(1, int(reach * size))
        lim = H if axis == 1 else W

        def profile(cells, edge):
            acc = np.zeros(2 * r + 1)
            n = 0
            for c in cells:
                lo = int(round(c[edge])) - r
                if lo < 0 or lo + 2 * r + 1 > lim:
                    continue
                c0, c1 = int(c[cross[0]] + 0.2 * (c[cross[1]] - c[cross[0]])), int(c[cross[1]] - 0.2 * (c[cross[1]] - c[cross[0]]))
                if axis == 1:
                    acc += grad[1][lo: lo + 2 * r + 1, c0:c1].mean(axis=1)
                else:
                    acc += grad[0][c0:c1, lo: lo + 2 * r + 1].mean(axis=0)
                n += 1
            return acc if n else None

        # calibrate: where the strongest edge lies from the drawn edge, on the unit itself
        offs = []
        for edge in (a, b):
            p = profile([unit], edge)
            offs.append(0 if p is None else r - int(np.argmax(p)))
        for grp in _groups(boxes[:, a], size):
            cells = boxes[grp]
            for k, edge in enumerate((a, b)):
                p = profile(cells, edge)
                if p is None:
                    continue
                shift = int(np.argmax(p)) - r + offs[k]
                out[grp, edge] = boxes[grp, edge] + shift
    bad = (out[:, 2] - out[:, 0] < 0.5 * w) | (out[:, 3] - out[:, 1] < 0.5 * h)
    out[bad] = boxes[bad]
    return out


def snap(grey, boxes, reach=0.2):
    g = cv2.GaussianBlur(grey.astype(np.float32), (0, 0), 1.0)
    gx = np.abs(cv2.Sobel(g, cv2.CV_32F, 1, 0))
    gy = np.abs(cv2.Sobel(g, cv2.CV_32F, 0, 1))
    H, W = g.shape
    out = boxes.copy()
    for i, (x0, y0, x1, y1) in enumerate(boxes):
        w, h = x1 - x0, y1 - y0
        rx, ry = max(1, int(reach * w)), max(1, int(reach * h))
        ya, yb = int(y0 + 0.2 * h), int(y1 - 0.2 * h)
        xa, xb = int(x0 + 0.2 * w), int(x1 - 0.2 * w)
        for j, (c, r_, prof_fn) in enumerate(((x0, rx, lambda lo, hi: gx[ya:yb, lo:hi].mean(axis=0)),
                                              (y0, ry, lambda lo, hi: gy[lo:hi, xa:xb].mean(axis=1)),
                                              (x1, rx, lambda lo, hi: gx[ya:yb, lo:hi].mean(axis=0)),
                                              (y1, ry, lambda lo, hi: gy[lo:hi, xa:xb].mean(axis=1)))):
            lim = W if j % 2 == 0 else H
            lo, hi = max(0, int(c) - r_), min(lim, int(c) + r_ + 1)
            if hi - lo < 3:
                continue
            p = prof_fn(lo, hi)
            if len(p):
                out[i, j] = lo + int(np.argmax(p))
    bad = (out[:, 2] - out[:, 0] < 0.5 * (boxes[:, 2] - boxes[:, 0])) | (out[:, 3] - out[:, 1] < 0.5 * (boxes[:, 3] - boxes[:, 1]))
    out[bad] = boxes[bad]
    return out


def method_module(grey, unit, wins_drawn):
    lv = appearance.Levels(grey.astype(np.float32))
    return _copies.find_copies(lv, unit[None], (unit[2] - unit[0], unit[3] - unit[1]))


METHODS = {"module": method_module, "ncc": method_ncc, "lattice": method_lattice,
           "lattice-raw": lambda g, u, d: method_lattice(g, u, d, norm=False),
           "lattice-nosize": lambda g, u, d: method_lattice(g, u, d, size=False),
           "lattice-bands": lambda g, u, d: method_lattice(g, u, d, size="bands")}
names = list(METHODS) if args.method == "all" else args.method.split(",")
stats = {n: {"found": [], "prec": [], "prec8": [], "t": []} for n in names}
from PIL import Image

for rid, seg in load_records(DEFAULT_CMP, args.limit)[:: args.every]:
    try:
        photo = Image.open(f"{args.photos}/{rid}.jpg").convert("L").resize((seg.width, seg.height))
    except FileNotFoundError:
        continue
    grey = np.asarray(photo, np.float32)
    rows = seg.to_array()
    wins = rows[rows[:, 0] == 1, 1:].astype(float) if False else None
    from facaid.labels import LABEL_ID
    wins = rows[rows[:, 0] == LABEL_ID["window"], 1:].astype(float)
    if len(wins) < 3:
        continue
    u = pick_unit(wins)
    others = np.delete(wins, u, axis=0)
    line = [rid]
    for n in names:
        t0 = time.perf_counter()
        boxes, sims = METHODS[n](grey, wins[u], wins[[u]])
        stats[n]["t"].append(time.perf_counter() - t0)
        keep = np.array([iou(b, wins[[u]])[0] < 0.5 for b in boxes], bool) if len(boxes) else np.zeros(0, bool)
        boxes, sims = boxes[keep], sims[keep]
        hit = np.array([(iou(b, others) >= 0.7).any() for b in boxes], bool)
        found = sum((iou(o, boxes) >= 0.7).any() for o in others) / len(others) if len(boxes) else 0.0
        stats[n]["found"].append(found)
        uw, uh = wins[u, 2] - wins[u, 0], wins[u, 3] - wins[u, 1]
        cx, cy = (others[:, 0] + others[:, 2]) / 2, (others[:, 1] + others[:, 3]) / 2
        same = np.stack([cx - uw / 2, cy - uh / 2, cx + uw / 2, cy + uh / 2], 1)
        hittable = np.array([iou(a, b[None])[0] >= 0.7 for a, b in zip(same, others)])
        near = np.array([(iou(o, boxes) >= 0.3).any() if len(boxes) else False for o in others])
        stats[n].setdefault("hittable", []).append(hittable.mean())
        stats[n].setdefault("near", []).append(near.mean())
        stats[n]["prec"].append(hit.mean() if len(hit) else np.nan)
        line.append(f"{n} {found:.2f}/{hit.mean() if len(hit) else float('nan'):.2f} ({len(boxes)})")
    print(*line, flush=True)
for n in names:
    s = stats[n]
    print(f"{n:16s} found {np.mean(s['found']):.3f} precision {np.nanmean(s['prec']):.3f} "
          f"seconds {statistics.median(s['t']):.3f}  ({len(s['found'])} facades) hittable {np.mean(s['hittable']):.3f} "
          f"located (IoU 0.3) {np.mean(s['near']):.3f}")
