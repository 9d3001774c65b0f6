"""Rendering label maps to pictures: the documented palette, overlays on photos, side-by-side strips, and SVG."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from facaid.labels import LABELS, PALETTE, PALETTE_ARRAY, hex_colour
from facaid.segmentation import Segmentation, paint_order, rasterize

_LUT = np.array(PALETTE_ARRAY, dtype=np.uint8)


def colorize(label_map: np.ndarray) -> Image.Image:
    """An RGB picture of a (H, W) label map in the palette of `facaid.labels`."""
    return Image.fromarray(_LUT[label_map], mode="RGB")


def render_segmentation(seg: Segmentation, *, outline: bool = False) -> Image.Image:
    """The segmentation painted in the paint order; with ``outline``, element edges are drawn darker."""
    image = colorize(rasterize(seg))
    if outline:
        draw = ImageDraw.Draw(image)
        for r in seg.rects:
            if LABELS[r.label] != "facade":
                draw.rectangle([r.x0, r.y0, r.x1 - 1, r.y1 - 1], outline=(20, 20, 20))
    return image


def overlay(photo: Image.Image, label_map: np.ndarray, alpha: float = 0.5) -> Image.Image:
    """Blend the coloured label map over a photo (resized to the label map) with the given opacity."""
    if not 0.0 <= alpha <= 1.0:
        raise ValueError(f"alpha must be between 0 and 1, got {alpha!r}")
    h, w = label_map.shape
    base = photo.convert("RGB")
    if base.size != (w, h):
        base = base.resize((w, h), Image.Resampling.BILINEAR)
    return Image.blend(base, colorize(label_map), alpha)


def legend(height: int = 24) -> Image.Image:
    """A strip naming every label in its colour."""
    cell = 96
    image = Image.new("RGB", (cell * len(LABELS), height), (255, 255, 255))
    draw = ImageDraw.Draw(image)
    for i, name in enumerate(LABELS):
        draw.rectangle([i * cell + 2, 4, i * cell + height - 6, height - 5], fill=PALETTE[name], outline=(0, 0, 0))
        draw.text((i * cell + height, height // 2 - 6), name, fill=(0, 0, 0))
    return image


def side_by_side(images: list[Image.Image], height: int = 256, gap: int = 8,
                 background: tuple[int, int, int] = (255, 255, 255)) -> Image.Image:
    """Images scaled to a common height and placed left to right."""
    scaled = [im.resize((max(1, round(im.width * height / im.height)), height), Image.Resampling.NEAREST)
              for im in images]
    width = sum(im.width for im in scaled) + gap * (len(scaled) + 1)
    out = Image.new("RGB", (width, height + 2 * gap), background)
    x = gap
    for im in scaled:
        out.paste(im, (x, gap))
        x += im.width + gap
    return out


def segmentation_svg(seg: Segmentation) -> str:
    """The segmentation as an SVG document of the same size: the background, then one group per class (``id`` the
    class name, its palette colour as ``fill``) holding its rectangles, in the paint order, so that the SVG draws
    exactly what `render_segmentation` paints: vector rectangles a drawing program can select class by class."""
    w, h = seg.width, seg.height
    lines = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" '
             'shape-rendering="crispEdges">',
             f'<rect id="background" width="{w}" height="{h}" fill="{hex_colour("background")}"/>']
    group = None
    for r in paint_order(seg.rects):
        name = LABELS[r.label]
        if name != group:
            if group is not None:
                lines.append("</g>")
            lines.append(f'<g id="{name}" fill="{hex_colour(name)}">')
            group = name
        lines.append(f'<rect x="{r.x0}" y="{r.y0}" width="{r.x1 - r.x0}" height="{r.y1 - r.y0}"/>')
    if group is not None:
        lines.append("</g>")
    lines.append("</svg>")
    return "\n".join(lines) + "\n"
