"""Pictures of procedures and segmentations for the site (PNG bytes)."""

from __future__ import annotations

import io

from PIL import Image

from facaid.render import overlay, render_segmentation
from facaid.segmentation import Segmentation as SegmentationData
from facaid.segmentation import rasterize

MAX_RENDER_SIDE = 2048


def _png(image: Image.Image) -> bytes:
    out = io.BytesIO()
    image.save(out, "PNG")
    return out.getvalue()


def _fit(image: Image.Image, max_side: int) -> Image.Image:
    scale = max_side / max(image.size)
    if scale >= 1:
        return image
    size = (max(1, round(image.width * scale)), max(1, round(image.height * scale)))
    return image.resize(size, Image.Resampling.NEAREST)


def label_map_png(seg: SegmentationData, max_side: int = MAX_RENDER_SIDE) -> bytes:
    return _png(_fit(render_segmentation(seg), max_side))


def overlay_png(seg: SegmentationData, photo: Image.Image, alpha: float = 0.5,
                max_side: int = MAX_RENDER_SIDE) -> bytes:
    return _png(_fit(overlay(photo, rasterize(seg), alpha), max_side))
