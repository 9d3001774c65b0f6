"""Corners: the facade ends where its bays stop repeating. Walk bay by bay outwards from the proposal's centre
(a full-height strip one bay wide, matched at the next bay's place), and trim the proposal's left and right sides
to where the walk stops. CMP dev photos (git-ignored cache), the upright proposals only.

    .venv/bin/python experiments/2026-12-07-bay-walk/proto.py [--stop 0.4] [--margin 0.25] [--colour 30]
"""
import argparse
import sys

import cv2
import numpy as np
from PIL import Image

sys.path.insert(0, "bench")
from bench_corners import facade_box, quad_iou  # noqa: E402

from facaid.evaluation.real import DEV_FACADES, load_records  # noqa: E402
from facaid.paths import DEFAULT_CMP  # noqa: E402
from facaid.photo.corners import propose_corners  # noqa: E402
from facaid.photo.repeats import normalised  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("--stop", type=float, default=0.4)
ap.add_argument("--margin", type=float, default=0.25)
ap.add_argument("--colour", type=float, default=1e9)
ap.add_argument("--method", default="run")
ap.add_argument("--ac", type=float, default=0.1)
ap.add_argument("--top", type=float, default=0.1)
ap.add_argument("--bottom", type=float, default=0.9)
ap.add_argument("--every", type=int, default=1)
ap.add_argument("--verbose", action="store_true")
args = ap.parse_args()
SIDE = 384


def pitch(profile, lo, hi):
    p = profile - profile.mean()
    ac = np.correlate(p, p, "full")[len(p) - 1:]
    ac = ac / max(ac[0], 1e-9)
    lags = np.arange(len(ac))
    ok = (lags >= lo) & (lags <= hi)
    # the first strong local maximum
    best = None
    for k in np.flatnonzero(ok):
        if 0 < k < len(ac) - 1 and ac[k] >= ac[k - 1] and ac[k] >= ac[k + 1] and ac[k] > 0.1:
            if best is None or ac[k] > ac[best] * 1.2:
                best = k if best is None or ac[k] > ac[best] else best
    return best


def ncc(a, b):
    a = a - a.mean()
    b = b - b.mean()
    d = np.sqrt((a * a).sum() * (b * b).sum())
    return float((a * b).sum() / d) if d > 1e-9 else 0.0


def run(norm, colour, x0, x1, y0, y1):
    """Left and right ends of the run of bays around the centre: where a strip one bay wide looks like the next."""
    band = norm[y0:y1]
    w = x1 - x0
    sub = band[:, x0:x1]
    lags = np.arange(max(6, w // 25), w // 3)
    ac = np.array([(sub[:, :-d] * sub[:, d:]).mean() for d in lags])
    ac = ac / max((sub * sub).mean(), 1e-9)
    peaks = [i for i in range(1, len(ac) - 1) if ac[i] >= ac[i - 1] and ac[i] >= ac[i + 1] and ac[i] > args.ac]
    if not peaks:
        return None
    p = int(lags[max(peaks, key=lambda i: ac[i])])
    n = norm.shape[1]
    s = np.full(n, -1.0)
    for x in range(0, n - 2 * p):
        s[x] = ncc(band[:, x:x + p], band[:, x + p:x + 2 * p])
    k = max(1, p // 2)
    sm = np.convolve(s, np.ones(k) / k, mode="same")
    c = (x0 + x1) // 2 - p
    if not 0 <= c < n or sm[c] < args.stop:
        return None
    a = c
    while a - 1 >= 0 and sm[a - 1] >= args.stop:
        a -= 1
    b = c
    while b + 1 < n - 2 * p and sm[b + 1] >= args.stop:
        b += 1
    return a, b + 2 * p, p


def walk(norm, colour, x0, x1, y0, y1):
    """Left and right ends (work pixels) of the bays around the centre of [x0, x1)."""
    band = norm[y0:y1, x0:x1]
    prof = np.abs(np.diff(band, axis=1)).mean(axis=0)
    w = x1 - x0
    p = pitch(prof, max(6, w // 25), w // 3)
    if p is None:
        return None
    c = (x0 + x1) // 2 - p // 2
    ref = [norm[y0:y1, c:c + p]]
    refc = colour[y0:y1, c:c + p].reshape(-1, 3).mean(axis=0)
    ends = []
    for step in (1, -1):
        at = c
        while True:
            best, where = -1.0, None
            for d in range(-p // 4, p // 4 + 1):
                s = at + step * p + d
                if s < 0 or s + p > norm.shape[1]:
                    continue
                v = max(ncc(r, norm[y0:y1, s:s + p]) for r in ref)
                if v > best:
                    best, where = v, s
            if where is None or best < args.stop:
                break
            col = colour[y0:y1, where:where + p].reshape(-1, 3).mean(axis=0)
            if np.abs(col - refc).max() > args.colour:
                break
            at = where
        ends.append(at + p if step == 1 else at)
    return ends[1], ends[0], p


out = []
for rid, seg in load_records(DEFAULT_CMP, DEV_FACADES)[:: args.every]:
    img = Image.open(f"var/cmp_photos/{rid}.jpg").convert("RGB")
    W, H = img.size
    found = propose_corners(img)
    q = np.array(found["corners"])
    box = facade_box(seg)
    sx, sy = W / seg.width, H / seg.height
    truth = [[box[0] * sx, box[1] * sy], [box[2] * sx, box[1] * sy], [box[2] * sx, box[3] * sy], [box[0] * sx, box[3] * sy]]
    before = quad_iou(q, truth, (W, H))
    f = SIDE / max(W, H)
    small = np.asarray(img.resize((round(W * f), round(H * f)), Image.BILINEAR), dtype=np.float32)
    grey = small.mean(axis=2)
    norm = normalised(grey, 0.02 * max(grey.shape))
    x0, x1 = int(q[:, 0].min() * f), int(q[:, 0].max() * f)
    y0, y1 = int(q[:, 1].min() * f), int(q[:, 1].max() * f)
    r = (run if args.method == "run" else walk)(norm, small, x0, x1, y0 + int(args.top * (y1 - y0)), y0 + int(args.bottom * (y1 - y0)))
    q2 = q.copy()
    if r is not None:
        left, right, p = r
        left, right = left - args.margin * p, right + args.margin * p
        if left > x0:
            q2[[0, 3], 0] = left / f
        if right < x1:
            q2[[1, 2], 0] = right / f
    after = quad_iou(q2, truth, (W, H))
    out.append((before, after))
    if args.verbose:
        print(rid, f"{before:.3f} -> {after:.3f}", r, (x0, x1), flush=True)
b = np.array(out)
print("improved", int((b[:, 1] > b[:, 0] + 0.05).sum()), "hurt", int((b[:, 1] < b[:, 0] - 0.05).sum()))
print(f"{len(b)} photos: median {np.median(b[:, 0]):.3f} -> {np.median(b[:, 1]):.3f}, >=0.85 "
      f"{(b[:, 0] >= 0.85).mean():.3f} -> {(b[:, 1] >= 0.85).mean():.3f}")
