"""Photo-like pictures of segmentations, for checking the parts of the product that read photos (corner proposals,
completion's photo checks) without shipping photos.

`render_photo(seg, seed)` paints a segmentation with materials instead of the palette: a textured wall, glass with
reflections, shutters with slats, shadows under sills and cornices, light falling off across the facade, sensor
noise and a little blur; the background class is sky. `warp(image, seed)` puts such a picture into a larger scene
as a camera would see it (a homography of the rectangle: keystone, yaw, a little roll) and returns the true
corners, in the order `facaid.photo.rectify.rectify` takes them, so that a test knows where the facade is.
Everything is deterministic by seed.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw, ImageFilter

from facaid.labels import LABEL_ID, LABELS
from facaid.photo.rectify import homography
from facaid.segmentation import Segmentation, rasterize

WALLS = ((205, 190, 165), (176, 98, 72), (150, 150, 148), (222, 214, 196), (196, 160, 96), (120, 112, 104))
SHUTTERS = ((62, 98, 60), (120, 78, 48), (90, 96, 104), (150, 60, 50))
SHADOWED = ("sill", "cornice", "balcony", "molding")  # what casts a shadow on the wall under it


def _smooth_noise(rng: np.random.Generator, shape: tuple[int, int], cells: int) -> np.ndarray:
    """Noise in [-1, 1] varying over about ``cells`` cells along the longer side (bicubic upsampling)."""
    h, w = shape
    gh, gw = max(2, round(cells * h / max(h, w)) + 2), max(2, round(cells * w / max(h, w)) + 2)
    grid = Image.fromarray(rng.uniform(0, 255, (gh, gw)).astype(np.uint8), "L")
    up = np.asarray(grid.resize((w, h), Image.Resampling.BICUBIC), dtype=np.float32)
    return up / 127.5 - 1.0


def _shift(colour, amount: float) -> np.ndarray:
    return np.clip(np.asarray(colour, dtype=np.float32) * amount, 0, 255)


def facade_box(seg: Segmentation) -> tuple[int, int, int, int]:
    """The box (x0, y0, x1, y1) of everything but the background: the building, without the sky beside it."""
    boxes = np.array([r[1:] for r in seg.rects if r.label != LABEL_ID["background"]] or [(0, 0, seg.width,
                                                                                          seg.height)])
    return int(boxes[:, 0].min()), int(boxes[:, 1].min()), int(boxes[:, 2].max()), int(boxes[:, 3].max())


def render_photo(seg: Segmentation, seed: int = 0, *, noise: float = 6.0, lighting: float = 0.2,
                 blur: float = 0.7) -> Image.Image:
    """The segmentation painted as a photo of a facade (an RGB image of its size); ``noise`` is the sensor noise's
    standard deviation in grey levels, ``lighting`` how much the light falls off across the facade, ``blur`` the
    lens's Gaussian radius in pixels."""
    rng = np.random.default_rng(seed)
    labels = rasterize(seg)
    h, w = labels.shape
    wall = np.asarray(WALLS[rng.integers(len(WALLS))], dtype=np.float32) * rng.uniform(0.96, 1.04, 3)
    out = np.empty((h, w, 3), dtype=np.float32)
    texture = 0.06 * _smooth_noise(rng, (h, w), 24) + 0.03 * _smooth_noise(rng, (h, w), 120)
    out[:] = wall * (1 + texture[..., None])

    ys = np.linspace(0, 1, h, dtype=np.float32)[:, None, None]
    sky = (1 - ys) * np.array([150, 185, 225], np.float32) + ys * np.array([215, 225, 235], np.float32)
    is_sky = labels == LABEL_ID["background"]
    out[is_sky] = np.broadcast_to(sky, (h, w, 3))[is_sky]

    stone = _shift(wall, 1.18)
    materials = {"cornice": stone, "molding": _shift(wall, 1.1), "deco": _shift(wall, 1.25), "sill": stone,
                 "pillar": _shift(wall, 0.92), "balcony": np.array([58, 58, 62], np.float32),
                 "door": np.array([92, 60, 38], np.float32) * rng.uniform(0.8, 1.2)}
    shutter = np.asarray(SHUTTERS[rng.integers(len(SHUTTERS))], np.float32)
    for r in seg.rects:
        name = LABELS[r.label]
        region = labels[r.y0:r.y1, r.x0:r.x1] == r.label
        if not region.any():
            continue
        tile = out[r.y0:r.y1, r.x0:r.x1]
        rh = r.y1 - r.y0
        if name in ("window", "shop"):
            # glass: dark, with the sky reflected more towards the top, each pane a little different
            t = np.linspace(0, 1, rh, dtype=np.float32)[:, None, None]
            top = rng.uniform(90, 150) if name == "window" else rng.uniform(120, 170)
            glass = top * (1 - t) + rng.uniform(30, 60) * t
            colour = np.broadcast_to(glass * np.array([0.8, 0.9, 1.05], np.float32), (*region.shape, 3))
            tile[region] = colour[region]
        elif name == "blind":
            slats = 1 + 0.12 * ((np.arange(rh) // 3) % 2)[:, None, None]
            colour = np.broadcast_to(shutter * slats, (*region.shape, 3))
            tile[region] = colour[region]
        elif name in materials:
            tile[region] = materials[name] * rng.uniform(0.95, 1.05)
        if name in SHADOWED:  # the wall under a ledge is in its shadow
            depth = max(2, rh // 2)
            below = labels[r.y1:r.y1 + depth, r.x0:r.x1] == LABEL_ID["facade"]
            out[r.y1:r.y1 + depth, r.x0:r.x1][below] *= 0.78

    light = 1 + lighting * (np.linspace(0.5, -0.5, w, dtype=np.float32)[None, :] * rng.choice([-1, 1])
                            + 0.5 * np.linspace(0.3, -0.3, h, dtype=np.float32)[:, None])
    out *= light[..., None]
    out += rng.normal(0, noise, out.shape).astype(np.float32)
    image = Image.fromarray(np.clip(out, 0, 255).astype(np.uint8), "RGB")
    return image.filter(ImageFilter.GaussianBlur(blur)) if blur > 0 else image


def random_corners(size: tuple[int, int], canvas: tuple[int, int], rng: np.random.Generator,
                   strength: float = 0.25) -> list[list[float]]:
    """Where a camera might see a ``size`` facade in a ``canvas`` picture: keystone (the top narrower, as when
    looking up) and yaw (one side taller) up to ``strength``, a roll of up to 4 degrees, scaled to fill 55 to 80 %
    of the canvas and placed off centre; TL, TR, BR, BL."""
    w, h = size
    keystone, yaw = rng.uniform(0, strength), rng.uniform(-strength, strength)
    quad = np.array([[-w / 2 * (1 - keystone), -h / 2 * (1 - yaw)], [w / 2 * (1 - keystone), -h / 2 * (1 + yaw)],
                     [w / 2, h / 2 * (1 + yaw)], [-w / 2, h / 2 * (1 - yaw)]])
    roll = np.radians(rng.uniform(-4, 4))
    quad = quad @ np.array([[np.cos(roll), np.sin(roll)], [-np.sin(roll), np.cos(roll)]])
    span = quad.max(axis=0) - quad.min(axis=0)
    quad *= rng.uniform(0.55, 0.8) * min(canvas[0] / span[0], canvas[1] / span[1])
    lo, hi = quad.min(axis=0), quad.max(axis=0)
    room = np.asarray(canvas, float) - (hi - lo)
    offset = -lo + room * rng.uniform(0.2, 0.8, 2)
    return (quad + offset).tolist()


def scene(canvas: tuple[int, int], rng: np.random.Generator) -> Image.Image:
    """What lies around the facade: sky above a street, smooth variations, some clutter (trees, signs, wires)."""
    w, h = canvas
    ys = np.linspace(0, 1, h, dtype=np.float32)[:, None, None]
    horizon = rng.uniform(0.55, 0.75)
    sky = (1 - ys) * np.array([120, 160, 210], np.float32) + ys * np.array([200, 210, 225], np.float32)
    ground = np.array([95, 92, 88], np.float32) * (1 + 0.3 * (ys - horizon))
    out = np.where(ys < horizon, sky, ground) * np.ones((1, w, 1), np.float32)
    out *= 1 + 0.08 * _smooth_noise(rng, (h, w), 8)[..., None]
    image = Image.fromarray(np.clip(out, 0, 255).astype(np.uint8), "RGB")
    draw = ImageDraw.Draw(image)
    for _ in range(int(rng.integers(3, 8))):  # trees and bushes
        cx, cy, r = rng.uniform(0, w), rng.uniform(0.4 * h, h), rng.uniform(0.03, 0.1) * max(w, h)
        draw.ellipse([cx - r, cy - r, cx + r, cy + 0.7 * r], fill=tuple(int(c) for c in rng.uniform(30, 110, 3)))
    for _ in range(int(rng.integers(2, 6))):  # wires, poles, signs: straight lines of any direction
        x0, y0, x1, y1 = rng.uniform(0, 1, 4) * [w, h, w, h]
        draw.line([x0, y0, x1, y1], fill=tuple(int(c) for c in rng.uniform(20, 80, 3)),
                  width=int(rng.integers(1, 4)))
    return image.filter(ImageFilter.GaussianBlur(1.0))


def warp(image: Image.Image, seed: int = 0, *, corners=None, canvas: tuple[int, int] | None = None,
         strength: float = 0.25, noise: float = 3.0) -> tuple[Image.Image, list[list[float]]]:
    """``image`` seen in perspective in a larger scene: the picture and the four corners (TL, TR, BR, BL, in its
    pixels) the image's corners went to. ``corners`` (default `random_corners` by seed) and ``canvas`` (default
    1.5 times the image's size) set the view."""
    rng = np.random.default_rng(seed)
    w, h = image.size
    canvas = canvas or (round(1.5 * w), round(1.5 * h))
    quad = np.asarray(corners if corners is not None else random_corners((w, h), canvas, rng, strength), float)
    back = homography(quad, [(0, 0), (w, 0), (w, h), (0, h)])  # PIL maps the canvas's pixels into the image
    coeffs = tuple((back / back[2, 2]).flatten()[:8])
    warped = image.convert("RGB").transform(canvas, Image.Transform.PERSPECTIVE, coeffs, Image.Resampling.BICUBIC)
    mask = Image.new("L", (w, h), 255).transform(canvas, Image.Transform.PERSPECTIVE, coeffs,
                                                 Image.Resampling.BILINEAR)
    out = scene(canvas, rng)
    out.paste(warped, (0, 0), mask)
    pixels = np.asarray(out, dtype=np.float32) + rng.normal(0, noise, (canvas[1], canvas[0], 3))
    return Image.fromarray(np.clip(pixels, 0, 255).astype(np.uint8), "RGB"), quad.tolist()
