"""Line segments of a photo and the vanishing points of their two families (a facade's horizontals and verticals).

Coordinates here are normalized: the image centre is the origin and half the longer side is 1, so that points and
lines are homogeneous 3-vectors of comparable magnitude and a vanishing point at infinity is one like any other.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FAMILY_SPREAD_DEG = 35.0  # how far from the image's axes a segment of a facade's horizontals or verticals may lean
INLIER_DEG = 1.5  # a segment agrees with a vanishing point when it points at it within this angle
RANSAC_ROUNDS = 300


def detect_segments(*channels: np.ndarray) -> np.ndarray:
    """Line segments (N, 5) of uint8 images of one size: x0, y0, x1, y1 in their pixels and the length, by OpenCV's
    line segment detector (LSD: no thresholds to tune, sub-pixel ends), those of every channel together."""
    import cv2

    lsd = cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD)
    found = [lines.reshape(-1, 4) for lines in (lsd.detect(c)[0] for c in channels) if lines is not None]
    if not found:
        return np.zeros((0, 5))
    segs = np.concatenate(found).astype(np.float64)
    length = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    return np.column_stack([segs, length])


def normalize(points: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """Pixel coordinates (..., 2) to the normalized frame of an image of ``size`` (w, h)."""
    w, h = size
    return (points - np.array([w / 2, h / 2])) / (max(w, h) / 2)


def denormalize(points: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    w, h = size
    return points * (max(w, h) / 2) + np.array([w / 2, h / 2])


def split_families(segs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The segments that lean less than `FAMILY_SPREAD_DEG` from the horizontal, and those from the vertical."""
    angle = np.degrees(np.arctan2(segs[:, 3] - segs[:, 1], segs[:, 2] - segs[:, 0])) % 180
    horizontal = (angle < FAMILY_SPREAD_DEG) | (angle > 180 - FAMILY_SPREAD_DEG)
    vertical = np.abs(angle - 90) < FAMILY_SPREAD_DEG
    return segs[horizontal], segs[vertical]


@dataclass
class Family:
    """A family of segments (normalized ends (N, 2, 2), lengths) with their vanishing point (a unit 3-vector)
    and which segments agree with it."""

    ends: np.ndarray
    lengths: np.ndarray
    point: np.ndarray
    inliers: np.ndarray

    @property
    def support(self) -> float:
        return float(self.lengths[self.inliers].sum())


def _lines(ends: np.ndarray) -> np.ndarray:
    """The homogeneous lines (N, 3) through the segments' ends, scaled so that (a, b) is a unit normal."""
    p = np.concatenate([ends, np.ones((*ends.shape[:2], 1))], axis=2)
    lines = np.cross(p[:, 0], p[:, 1])
    return lines / np.linalg.norm(lines[:, :2], axis=1, keepdims=True)


def _agreement(ends: np.ndarray, points: np.ndarray) -> np.ndarray:
    """|cos| of the angle between each segment (N) and the direction from its midpoint to each vanishing point
    (K, 3): (K, N)."""
    mid = ends.mean(axis=1)  # (N, 2)
    d = ends[:, 1] - ends[:, 0]
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    towards = points[:, None, :2] - points[:, None, 2:3] * mid[None]  # (K, N, 2): v - w * m, up to sign
    norm = np.linalg.norm(towards, axis=2)
    cos = np.abs((towards * d[None]).sum(axis=2)) / np.maximum(norm, 1e-12)
    return np.where(norm > 1e-12, cos, 0.0)


def _refine(lines: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """The point nearest all the lines (least squares of l . v with |v| = 1, weighted)."""
    scatter = (lines * weights[:, None]).T @ lines
    return np.linalg.eigh(scatter)[1][:, 0]


def vanishing_point(ends: np.ndarray, lengths: np.ndarray, rng: np.random.Generator) -> Family | None:
    """The vanishing point most of the segments agree with (each voting with the square root of its length):
    RANSAC over pairs (drawn by their votes), then least squares on the agreeing segments; None for fewer than 3
    segments or no pair agreeing."""
    n = len(ends)
    if n < 3:
        return None
    lines = _lines(ends)
    # votes grow with the square root of the length: a facade's many short window edges outvote a few long wires
    votes = np.sqrt(lengths)
    p = votes / votes.sum()
    pairs = rng.choice(n, size=(RANSAC_ROUNDS, 2), p=p)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    candidates = np.cross(lines[pairs[:, 0]], lines[pairs[:, 1]])
    norm = np.linalg.norm(candidates, axis=1)
    candidates = candidates[norm > 1e-12] / norm[norm > 1e-12, None]
    if len(candidates) == 0:
        return None
    threshold = np.cos(np.radians(INLIER_DEG))
    scores = ((_agreement(ends, candidates) >= threshold) * votes).sum(axis=1)
    point = candidates[int(np.argmax(scores))]
    for _ in range(3):  # refine on the agreeing segments, which may then change
        inliers = _agreement(ends, point[None])[0] >= threshold
        if inliers.sum() < 2:
            return None
        point = _refine(lines[inliers], votes[inliers])
    inliers = _agreement(ends, point[None])[0] >= threshold
    return Family(ends, lengths, point, inliers)


def affine_frame(horizontal: np.ndarray, vertical: np.ndarray) -> np.ndarray:
    """The homography H (normalized image -> a frame where the facade's horizontals are horizontal and its
    verticals vertical) that sends the two vanishing points to infinity and keeps the image centre at the origin,
    right still to the right and down still down."""
    vh = horizontal * (1 if horizontal[0] >= 0 else -1)  # the same points; the signs fix the frame's orientation
    vv = vertical * (1 if vertical[1] >= 0 else -1)
    return np.linalg.inv(np.column_stack([vh, vv, [0.0, 0.0, 1.0]]))


def apply(h: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points (..., 2) through a homography: the mapped points and the sign of their homogeneous weight (points
    beyond the vanishing line come out with a negative one)."""
    p = np.concatenate([points, np.ones((*points.shape[:-1], 1))], axis=-1) @ h.T
    w = p[..., 2]
    safe = np.where(np.abs(w) < 1e-12, 1e-12, w)
    return p[..., :2] / safe[..., None], np.sign(w)
