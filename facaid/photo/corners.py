"""The facade's four corners proposed from a photo's straight lines (`propose_corners`), for `facaid.photo.rectify`
to warp: line segments, their two vanishing points, the outermost strong lines of each family, a head-on photo's
sides moved out where the facade goes on, and no-data wedges left out (`facaid.photo.nodata`)."""

from __future__ import annotations

import numpy as np
from PIL import Image

from facaid.photo.nodata import clear_of, data_edges, nodata_mask, off_wedges
from facaid.photo.rectify import check_corners
from facaid.photo.vanishing import (
    Family,
    affine_frame,
    apply,
    denormalize,
    detect_segments,
    normalize,
    split_families,
    vanishing_point,
)

WORK_SIDE = 640  # the photo is searched at this size (its longer side): LSD takes ~50 ms there on one core
MIN_WORK_SIDE = 24  # smaller than this, there are no lines to find
MIN_LENGTH = 0.02  # of the longer side: shorter segments are texture, not the facade's lines
STRONG = 0.15  # a boundary line has at least this share of the strongest line's support in its family
MIN_SPAN = 0.1  # the boundaries of a family lie at least this far apart (of the frame's extent), or they are noise
EXTENT_WIDEN = 0.03
MERGE_PX = 3.0  # segments whose lines lie within this many work pixels are one line
DEEP = 0.1  # a wedge that takes this share of the proposal along cuts into the facade: the note says how much


def _work_channels(image: Image.Image) -> list[np.ndarray]:
    """The photo at most `WORK_SIDE` pixels a side as uint8 images to find edges in, whatever its mode: its
    luminance, and for a colour photo two opponent channels (blue-yellow, red-green), for a facade as bright as the
    sky beside it differs in colour. Transparency lies over mid grey; 16-bit and float images are stretched to their
    range. The photo is shrunk first, so that no full-size copy of it is made but for a palette or bilevel one."""
    w, h = image.size
    scale = min(1.0, WORK_SIDE / max(w, h))
    size = (max(1, round(w * scale)), max(1, round(h * scale)))
    if image.mode == "P":
        image = image.convert("RGBA" if "transparency" in image.info else "RGB")
    elif image.mode in ("1", "I;16B", "I;16L", "I;16N"):
        image = image.convert("L" if image.mode == "1" else "I")
    if size != (w, h):
        image = image.resize(size, Image.Resampling.BILINEAR, reducing_gap=2.0)
    if image.mode in ("I", "I;16", "F"):
        a = np.nan_to_num(np.asarray(image, dtype=np.float64))
        lo, hi = float(a.min()), float(a.max())
        return [((a - lo) * (255.0 / (hi - lo)) if hi > lo else np.zeros_like(a)).astype(np.uint8)]
    if image.mode in ("RGBA", "LA", "PA", "La", "RGBa"):
        image = Image.alpha_composite(Image.new("RGBA", image.size, (128, 128, 128, 255)), image.convert("RGBA"))
    if image.mode == "L":
        return [np.asarray(image, dtype=np.uint8)]
    c = np.asarray(image.convert("RGB"), dtype=np.float32)
    r, g, b = c[..., 0], c[..., 1], c[..., 2]
    luma = 0.299 * r + 0.587 * g + 0.114 * b
    channels = [luma, 128 + (b - (r + g) / 2) / 2, 128 + (r - g) / 2]
    return [np.clip(ch, 0, 255).astype(np.uint8) for ch in channels]


def _frame_segments(frame: np.ndarray, family: Family | None) -> np.ndarray:
    """The family's agreeing segments' ends (N, 2, 2) in the frame, less those beyond the vanishing line (which
    are not on the facade)."""
    if family is None:
        return np.zeros((0, 2, 2))
    ends, sign = apply(frame, family.ends[family.inliers])
    return ends[(sign > 0).all(axis=1)]


def _lines(ends: np.ndarray, axis: int, tol: float) -> np.ndarray:
    """A family's segments (ends (N, 2, 2) in the frame) merged into lines where their positions along ``axis``
    (1 for the horizontals' v, 0 for the verticals' u) lie within ``tol`` of their neighbours': rows of (position,
    covered length, first, last) in order of position. The position is the length-weighted mean; the covered length
    the union of the spans, not their sum, for a stretch of edge found twice (in two channels) counts once."""
    positions = ends[:, :, axis].mean(axis=1)
    spans = np.sort(ends[:, :, 1 - axis], axis=1)
    order = np.argsort(positions)
    p, sp = positions[order], spans[order]
    starts = np.concatenate([[0], np.flatnonzero(np.diff(p) > tol) + 1])
    stops = np.concatenate([starts[1:], [len(p)]])
    out = np.empty((len(starts), 4))
    for k, (a, b) in enumerate(zip(starts, stops, strict=True)):
        group = sp[a:b][np.argsort(sp[a:b, 0])]
        total, reach = 0.0, -np.inf
        for lo, hi in group:
            if hi > reach:
                total += hi - max(lo, reach)
                reach = hi
        out[k] = np.average(p[a:b], weights=group[:, 1] - group[:, 0] + 1e-12), total, group[:, 0].min(), reach
    return out


def _strong(lines: np.ndarray) -> np.ndarray:
    return lines[lines[:, 1] >= STRONG * lines[:, 1].max()] if len(lines) else lines


def _extent(lines: np.ndarray) -> tuple[float, float] | None:
    """Where the strong lines of a family reach (along their own direction), widened by `EXTENT_WIDEN`: the facade's
    lines end at its sides, where a wire or a tree edge beside it goes on."""
    strong = _strong(lines)
    if len(strong) < 2:
        return None
    lo, hi = strong[:, 2].min(), strong[:, 3].max()
    return lo - EXTENT_WIDEN * (hi - lo), hi + EXTENT_WIDEN * (hi - lo)


def _boundaries(lines: np.ndarray, within: tuple[float, float] | None, tol: float):
    """The outermost strong lines (position, covered length) of a family, of those ``within`` where the other
    family's strong lines reach; None when there are no two far enough apart."""
    if within is not None:
        lines = lines[(lines[:, 0] >= within[0]) & (lines[:, 0] <= within[1])]
    strong = _strong(lines)
    if len(strong) < 2:
        return None
    first, last = strong[0], strong[-1]
    if last[0] - first[0] < MIN_SPAN * max(lines[-1, 0] - lines[0, 0], tol):
        return None
    return (first[0], first[1]), (last[0], last[1])


def _family(segs: np.ndarray, size: tuple[int, int], rng: np.random.Generator) -> Family | None:
    """The segments' vanishing point, if at least 3 segments agree with it."""
    found = vanishing_point(normalize(segs[:, :4].reshape(-1, 2, 2), size), segs[:, 4], rng)
    return found if found is not None and found.inliers.sum() >= 3 else None


def _tolerance(frame: np.ndarray, size: tuple[int, int]) -> float:
    """`MERGE_PX` work pixels at the image centre, in the frame's units."""
    px = 2.0 / max(size)
    step = np.linalg.norm(apply(frame, np.array([[px, 0.0], [0.0, px], [0.0, 0.0]]))[0][:2], axis=1).mean()
    return MERGE_PX * step


def _region(frame: np.ndarray, family: Family, segs: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """Which segments (N, 5, in work pixels) have their middle in the box of the family's strong lines in the frame
    (their extent, between the outermost two), widened by a tenth; all of them when the family outlines nothing."""
    lines = _strong(_lines(_frame_segments(frame, family), 1, _tolerance(frame, size)))
    if len(lines) < 2:
        return np.ones(len(segs), bool)
    u0, u1, v0, v1 = lines[:, 2].min(), lines[:, 3].max(), lines[0, 0], lines[-1, 0]
    du, dv = 0.1 * (u1 - u0), 0.1 * (v1 - v0)
    mid, sign = apply(frame, normalize((segs[:, :2] + segs[:, 2:4]) / 2, size))
    return (sign > 0) & (mid[:, 0] >= u0 - du) & (mid[:, 0] <= u1 + du) & (mid[:, 1] >= v0 - dv) & \
        (mid[:, 1] <= v1 + dv)


UPRIGHT_DEG = 1.0  # a quadrilateral whose sides all lie this close to the photo's axes: a fronto-parallel photo
BUSY = 0.3  # a band beside it with this share of the lines per area inside is more of the facade
COLOUR = 12  # ... and so is one whose median colour is this close (grey levels, every channel) to the box's


def _upright(pts: np.ndarray) -> bool:
    """Whether the four sides of the quadrilateral (TL, TR, BR, BL) lie within `UPRIGHT_DEG` of the photo's axes."""
    d = np.roll(pts, -1, axis=0) - pts
    angles = np.degrees(np.arctan2(d[:, 1], d[:, 0])) % 90
    return bool(np.all(np.minimum(angles, 90 - angles) <= UPRIGHT_DEG))


def _widened(pts: np.ndarray, segs: np.ndarray, picture: np.ndarray, nodata: np.ndarray) -> np.ndarray:
    """A fronto-parallel facade's box (work pixels) moved out to the photo's edge on each side where the band between
    them is more of the facade: its colour that of the box (`COLOUR`: the wall goes on beyond the outermost
    windows) or as many lines per area (`BUSY`). The outermost strong lines of a rectified photo are often a
    window column's or a shop sign's, inside the facade (issue 57: the proposal cut a bay or a floor off most
    rectified photos). The photo's edge is where its data ends: a no-data wedge (``nodata``) is no band's."""
    h, w = picture.shape[:2]
    x0, y0 = pts[:, 0].min(), pts[:, 1].min()
    x1, y1 = pts[:, 0].max(), pts[:, 1].max()
    mid = (segs[:, :2] + segs[:, 2:4]) / 2

    def density(a, b, c, d) -> float:
        area = max(c - a, 1.0) * max(d - b, 1.0)
        inside = (mid[:, 0] >= a) & (mid[:, 0] < c) & (mid[:, 1] >= b) & (mid[:, 1] < d)
        return float(segs[inside, 4].sum() / area)

    def colour(a, b, c, d) -> np.ndarray:
        rows, cols = slice(int(b), max(int(b) + 1, int(d))), slice(int(a), max(int(a) + 1, int(c)))
        region = picture[rows, cols][~nodata[rows, cols]]
        if not region.size:
            return np.full(picture.shape[2], np.inf)
        return np.median(region.reshape(-1, picture.shape[2]), axis=0)

    box, wall = density(x0, y0, x1, y1), colour(x0, y0, x1, y1)
    out = np.array([x0, y0, x1, y1], dtype=float)
    edges = data_edges(nodata, (x0, y0, x1, y1))
    for i, band in enumerate(((edges[0], y0, x0, y1), (x0, edges[1], x1, y0), (x1, y0, edges[2], y1),
                              (x0, y1, x1, edges[3]))):
        if min(band[2] - band[0], band[3] - band[1]) < 1:
            continue
        same = bool(np.isfinite(wall).all()) and float(np.abs(colour(*band) - wall).max()) <= COLOUR
        busy = box > 0 and density(*band) >= BUSY * box
        if same or busy:
            out[i] = edges[i]
    return np.array([[out[0], out[1]], [out[2], out[1]], [out[2], out[3]], [out[0], out[3]]])


def _fallback(w: int, h: int, note: str) -> dict:
    return {"corners": [[0.0, 0.0], [float(w), 0.0], [float(w), float(h)], [0.0, float(h)]], "confidence": 0.0,
            "notes": [note, "the photo's own corners are proposed: drag them onto the facade's"],
            "lines": {"horizontal": 0, "vertical": 0}}


def propose_corners(image: Image.Image) -> dict:
    """Four corners of the facade in a photo, found from its straight lines: ``{"corners": [[x, y] x 4] (TL, TR,
    BR, BL, in the photo's pixels, as `rectify` takes them), "confidence": 0..1, "notes": [...], "lines":
    {"horizontal": n, "vertical": n}}``.

    Line segments (LSD) at `WORK_SIDE` pixels are split into near-horizontal and near-vertical families; each
    family's vanishing point is found by RANSAC over pairs of segments and least squares; in the frame where both
    vanishing points lie at infinity, the facade is bounded by each family's outermost strong lines (of at least
    `STRONG` times the strongest one's length). A family without two such lines is bounded by the photo's edges.
    ``confidence`` is the share of the quadrilateral's four sides that detected segments cover (0 for a side that
    is the photo's edge); ``notes`` say what was guessed. No-data wedges at the photo's edges (an earlier
    rectification's pure black or white) are no facade: their borders do not vote, and the quadrilateral is moved off
    them (`facaid.photo.nodata`); where that leaves out a part of the facade (`DEEP`), ``"whole"`` holds the corners
    with the wedge in, for the person to choose. Never raises for an image PIL decoded."""
    w, h = image.size
    if min(w, h) < 1:
        return _fallback(w, h, "the photo is empty")
    channels = _work_channels(image)
    gh, gw = channels[0].shape
    if min(gw, gh) < MIN_WORK_SIDE:
        return _fallback(w, h, f"the photo is too small or too narrow to find lines in ({w}x{h})")
    nodata = nodata_mask(_nearest_luma(image, (gw, gh), channels[0]))
    found = _from_lines((w, h), channels, nodata)
    if nodata.any():
        scale = np.array([w / gw, h / gh])
        pts = np.array(found["corners"]) / scale
        cleared, lost = clear_of(pts, nodata)
        if np.abs(cleared - pts).max() * scale.max() > 0.5:
            if lost >= DEEP:  # the facade as its lines bound it, wedge and all: the person's other choice
                found["whole"] = found["corners"]
            found["corners"] = [[round(float(x), 2), round(float(y), 2)] for x, y in cleared * scale]
            found["notes"].append(_left_out(lost))
    return found


def _nearest_luma(image: Image.Image, size: tuple[int, int], luma: np.ndarray) -> np.ndarray:
    """The photo's luminance at the work ``size``, each pixel one of the photo's (not a blend): a wedge's thin black
    sliver stays pure black, as a bilinear shrink would grey it. ``luma`` (the work luminance) where the photo's
    mode has no plain grey level."""
    if image.mode not in ("RGB", "RGBA", "L", "LA", "CMYK", "YCbCr"):
        return luma
    return np.asarray(image.resize(size, Image.Resampling.NEAREST).convert("L"))


def _left_out(lost: float) -> str:
    """The note on a proposal moved off the photo's no-data wedges, which says how much of the facade went with them
    where a wedge cuts into it (``lost``: the share of the first proposal left out)."""
    note = "the photo's no-data wedges at its edges (pure black, white or flat grey) are left out"
    if lost >= DEEP:
        note += (f", and {lost:.0%} of the facade's quadrilateral with them, for a wedge cuts into it: \"Take in the "
                 "wedge\" proposes the whole facade, no data and all")
    return note


def _from_lines(size: tuple[int, int], channels: list[np.ndarray], nodata: np.ndarray) -> dict:
    """`propose_corners` from the photo's work channels, but for its no-data wedges' own step."""
    w, h = size
    gh, gw = channels[0].shape
    segs = detect_segments(*channels)
    segs = off_wedges(segs[segs[:, 4] >= MIN_LENGTH * max(gw, gh)], nodata)
    rng = np.random.default_rng(0)  # the same photo, the same proposal
    hs, vs = split_families(segs)
    fh = _family(hs, (gw, gh), rng)
    if fh is not None and len(vs) > 3:
        # the verticals that vote are those on the facade as its horizontals outline it: a pole, a wire or a tree's
        # edge beside it often outvotes a facade of few vertical edges (ribbon windows)
        inside = _region(affine_frame(fh.point, np.array([0, 1.0, 0])), fh, vs, (gw, gh))
        fv = _family(vs[inside], (gw, gh), rng) if inside.sum() >= 3 else None
        fv = fv if fv is not None else _family(vs, (gw, gh), rng)
    else:
        fv = _family(vs, (gw, gh), rng)
    counts = {"horizontal": int(fh.inliers.sum()) if fh else 0, "vertical": int(fv.inliers.sum()) if fv else 0}
    if fh is None and fv is None:
        return {**_fallback(w, h, "too few straight lines to find the facade"), "lines": counts}
    frame = affine_frame(fh.point if fh else np.array([1.0, 0, 0]), fv.point if fv else np.array([0, 1.0, 0]))
    if not np.isfinite(frame).all() or np.linalg.cond(frame) > 1e8:
        return {**_fallback(w, h, "the two families of lines meet in one point"), "lines": counts}
    tol = _tolerance(frame, (gw, gh))
    h_ends, v_ends = _frame_segments(frame, fh), _frame_segments(frame, fv)
    h_lines = _lines(h_ends, 1, tol) if len(h_ends) >= 2 else np.zeros((0, 4))
    v_lines = _lines(v_ends, 0, tol) if len(v_ends) >= 2 else np.zeros((0, 4))
    rows = _boundaries(h_lines, _extent(v_lines), tol)
    cols = _boundaries(v_lines, _extent(h_lines), tol)
    notes = []
    half = np.array([gw, gh]) / max(gw, gh)  # the image's half sides, normalized
    edges_y = [np.array([0.0, 1.0, half[1]]), np.array([0.0, 1.0, -half[1]])]  # y = -h/2, y = h/2
    edges_x = [np.array([1.0, 0.0, half[0]]), np.array([1.0, 0.0, -half[0]])]
    if rows is None:
        notes.append("no top and bottom lines found: the photo's top and bottom edges are proposed")
        top, bottom = edges_y
    else:
        top, bottom = (frame.T @ np.array([0.0, 1.0, -c]) for c, _ in rows)
    if cols is None:
        notes.append("no left and right lines found: the photo's left and right edges are proposed")
        left, right = edges_x
    else:
        left, right = (frame.T @ np.array([1.0, 0.0, -c]) for c, _ in cols)
    corners = np.array([np.cross(a, b) for a, b in ((top, left), (top, right), (bottom, right), (bottom, left))])
    if (np.abs(corners[:, 2]) < 1e-12).any():
        return {**_fallback(w, h, "the lines found do not close a quadrilateral"), "lines": counts}
    pts = denormalize(corners[:, :2] / corners[:, 2:], (gw, gh)) * np.array([w / gw, h / gh])

    # how much of each side the segments cover, in the frame: rows' support against the distance between the
    # columns, and the other way round
    frame_pts = apply(frame, normalize(pts / np.array([w / gw, h / gh]), (gw, gh)))[0]
    width = np.linalg.norm(frame_pts[1] - frame_pts[0]) + np.linalg.norm(frame_pts[2] - frame_pts[3])
    height = np.linalg.norm(frame_pts[3] - frame_pts[0]) + np.linalg.norm(frame_pts[2] - frame_pts[1])
    cover = [min(1.0, s / max(width / 2, 1e-12)) for _, s in rows] if rows else [0.0, 0.0]
    cover += [min(1.0, s / max(height / 2, 1e-12)) for _, s in cols] if cols else [0.0, 0.0]

    if _upright(pts):
        notes.append("the photo looks fronto-parallel already (the facade's lines are upright): rectifying it "
                     "changes little beyond the crop")
        scale = np.array([w / gw, h / gh])
        pts = _widened(pts / scale, segs, np.stack(channels, axis=-1), nodata) * scale

    outside = (pts < -0.5) | (pts > np.array([w, h]) + 0.5)
    if outside.any():
        notes.append("a corner found lies outside the photo: it is moved to the photo's edge")
        pts = np.clip(pts, 0, [w, h])
    try:
        check_corners(pts)
    except ValueError:
        return {**_fallback(w, h, "the lines found make no convex quadrilateral"), "lines": counts}
    area = 0.5 * abs(np.dot(pts[:, 0], np.roll(pts[:, 1], -1)) - np.dot(pts[:, 1], np.roll(pts[:, 0], -1)))
    if area < 0.02 * w * h:
        return {**_fallback(w, h, "the lines found enclose almost nothing"), "lines": counts}
    return {"corners": [[round(float(x), 2), round(float(y), 2)] for x, y in pts],
            "confidence": round(float(np.mean(cover)), 3), "notes": notes, "lines": counts}


def propose_corners_file(fp) -> dict:
    """`propose_corners` of the image in an open file, a JPEG decoded at a reduced size (its DCT scaling)."""
    image = Image.open(fp)
    size = image.size
    image.draft("RGB", (WORK_SIDE, WORK_SIDE))  # a JPEG decodes at 1/2, 1/4 or 1/8; other formats ignore it
    found = propose_corners(image)
    if image.size == size:
        return found
    sx, sy = size[0] / image.size[0], size[1] / image.size[1]
    found["corners"] = [[round(min(size[0], x * sx), 2), round(min(size[1], y * sy), 2)] for x, y in found["corners"]]
    return found
