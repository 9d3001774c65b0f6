"""Opening a photo the one way every reader of photos does: as a viewer shows it, and no larger than it is needed.

`read_photo` bounds what a read holds: a JPEG decodes at the smallest of its DCT scales (1/2, 1/4, 1/8) that is
still at least the size asked for (`draft`); a WebP is scaled by libwebp while it decodes (`facaid.photo.webp`); a
PNG asked for at half its size or less is decoded so by OpenCV, 2, 4 or 8 times smaller (`_png_reduced`), else
it decodes whole once and is converted and resized strip by strip (`resized`), so no second full-size copy exists
(PIL's own conversion, or a resize of an image with alpha, which premultiplies, makes one).
Modes are converted and the EXIF orientation applied after the reduction, on the small picture.
"""

from __future__ import annotations

import math
from typing import Any

from PIL import Image

ORIENTATION = 0x0112  # the EXIF tag
TURNED = (5, 6, 7, 8)  # orientations that turn the picture a quarter: the stored width is the upright height
STRIP_PIXELS = 1 << 20  # source pixels converted at a time (4 MB of RGBA): copies this small come and go


def orientation(image: Image.Image) -> int:
    """The EXIF orientation of an opened photo (1: stored upright). A PNG's is read from an eXIf chunk before its
    pixels only: PIL looks for one after them by decoding the whole picture first (0.2 s for 40 MP)."""
    if image.format == "PNG" and "exif" not in image.info:
        return 1
    return image.getexif().get(ORIENTATION, 1)


def resized(photo: Image.Image, size: tuple[int, int], mode: str, strip: int = STRIP_PIXELS) -> Image.Image:
    """``photo`` converted to ``mode`` and resized to ``size`` (bilinear, antialiased as PIL's `resize`), made strip
    by strip: each strip of output rows from the source rows its filter reaches (a margin either side), converted
    on its own, so the strips' copies are all it holds beside the result, and the result is a whole resize's (up
    to a level of rounding)."""
    w, h = photo.size
    width, height = size
    out = Image.new(mode, size)
    scale = h / height
    margin = math.ceil(max(scale, 1.0)) + 2  # the bilinear filter reaches one source pixel per output pixel's step
    rows = max(1, math.floor(strip / w / max(scale, 1.0)))
    for top in range(0, height, rows):
        bottom = min(height, top + rows)
        y0, y1 = top * scale, bottom * scale
        c0, c1 = max(0, math.floor(y0) - margin), min(h, math.ceil(y1) + margin)
        part = photo.crop((0, c0, w, c1)).convert(mode)
        out.paste(part.resize((width, bottom - top), Image.Resampling.BILINEAR, box=(0, y0 - c0, w, y1 - c0)),
                  (0, top))
    return out


def read_photo(source: Any, size: tuple[int, int] | None = None, mode: str | None = None,
               max_side: int | None = None) -> Image.Image:
    """The photo at ``source`` (a path or a binary file) as a viewer shows it (its EXIF orientation applied, the tag
    dropped), decoded now, at ``size`` (width, height as shown; by default its own, or with ``max_side``, its own
    shrunk to at most that many pixels a side) and in ``mode`` (by default its own). The size is reached from a
    reduced decode (see the module's docstring) by a bilinear resize. PIL's errors (OSError,
    `Image.DecompressionBombError`) pass through, and libwebp's as OSError."""
    with Image.open(source) as raw:
        turn = orientation(raw)
        if size is None and max_side is not None and max(raw.size) > max_side:
            f = max_side / max(raw.size)
            w, h = max(1, round(raw.width * f)), max(1, round(raw.height * f))
            size = (h, w) if turn in TURNED else (w, h)
        stored = size[::-1] if size is not None and turn in TURNED else size  # in the stored pixels' axes
        if raw.format == "WEBP":
            image = _webp(raw, stored, mode)
        elif raw.format == "PNG" and (reduced := _png_reduced(source, raw, stored, mode)) is not None:
            image = reduced
        else:
            if stored is not None:
                raw.draft(mode if mode in ("RGB", "L") else None, stored)  # JPEG only; a no-op for the rest
            raw.load()
            image = raw
            if (stored is not None and raw.size != tuple(stored)) or (mode is not None and raw.mode != mode):
                image = resized(raw, tuple(stored or raw.size), mode or raw.mode)
    if turn in TRANSPOSE:
        image = image.transpose(TRANSPOSE[turn])  # on the picture at the size asked for
    for key in ("exif", "xmp", "XML:com.adobe.xmp"):  # the tag dropped (an XMP one too), as the pixels are upright
        image.info.pop(key, None)
    image.getexif().pop(ORIENTATION, None)
    return image


TRANSPOSE = {2: Image.Transpose.FLIP_LEFT_RIGHT, 3: Image.Transpose.ROTATE_180, 4: Image.Transpose.FLIP_TOP_BOTTOM,
             5: Image.Transpose.TRANSPOSE, 6: Image.Transpose.ROTATE_270, 7: Image.Transpose.TRANSVERSE,
             8: Image.Transpose.ROTATE_90}  # what each EXIF orientation asks for (as `ImageOps.exif_transpose`)


def _png_reduced(source: Any, raw: Image.Image, size: tuple[int, int] | None, mode: str | None) -> Image.Image | None:
    """A PNG at ``size`` in ``mode`` (L or RGB) by OpenCV's reduced decode, where ``size`` is half its own or less
    (it decodes and shrinks by 2, 4 or 8 a row at a time: a 40 MP PNG to grey levels in 0.18 s, where PIL's decode
    and strip-wise resize took 0.4 s), then shrunk to ``size`` by area; None where that does not apply."""
    if size is None or mode not in ("L", "RGB"):
        return None
    factor = next((f for f in (8, 4, 2) if raw.width // f >= size[0] and raw.height // f >= size[1]), 1)
    if factor == 1:
        return None
    import cv2
    import numpy as np

    flags = {("L", 2): cv2.IMREAD_REDUCED_GRAYSCALE_2, ("L", 4): cv2.IMREAD_REDUCED_GRAYSCALE_4,
             ("L", 8): cv2.IMREAD_REDUCED_GRAYSCALE_8, ("RGB", 2): cv2.IMREAD_REDUCED_COLOR_2,
             ("RGB", 4): cv2.IMREAD_REDUCED_COLOR_4, ("RGB", 8): cv2.IMREAD_REDUCED_COLOR_8}
    if hasattr(source, "read"):
        source.seek(0)
        data = source.read()
    else:
        with open(source, "rb") as f:
            data = f.read()
    pixels = cv2.imdecode(np.frombuffer(data, dtype=np.uint8), flags[mode, factor] | cv2.IMREAD_IGNORE_ORIENTATION)
    del data
    if pixels is None or pixels.dtype != np.uint8:
        return None
    if (pixels.shape[1], pixels.shape[0]) != tuple(size):
        pixels = cv2.resize(pixels, tuple(size), interpolation=cv2.INTER_AREA)
    if mode == "RGB":
        pixels = cv2.cvtColor(pixels, cv2.COLOR_BGR2RGB)
    return Image.fromarray(pixels, mode)


def _webp(raw: Image.Image, size: tuple[int, int] | None, mode: str | None) -> Image.Image:
    from facaid.photo import webp

    raw.fp.seek(0)
    alpha = raw.mode == "RGBA" and mode in (None, "RGBA", "LA")
    pixels = webp.decode(raw.fp.read(), size, alpha=alpha)
    image = Image.fromarray(pixels, "RGBA" if alpha else "RGB")
    return image if mode is None or image.mode == mode else image.convert(mode)


def open_photo(source: Any, draft: tuple[int, int] | None = None, grey: bool = False) -> Image.Image:
    """The photo at ``source`` as a viewer shows it, decoded now (`read_photo`). With ``draft``, at the smallest of
    a JPEG's reduced scales that is still at least that size both ways (other formats at their own size); ``grey``
    decodes it as grey levels."""
    if draft is None:
        return read_photo(source, None, "L" if grey else None)
    with Image.open(source) as raw:
        turned = orientation(raw) in TURNED
        raw.draft("L" if grey else "RGB", draft[::-1] if turned else draft)
        size = raw.size[::-1] if turned else raw.size
    if hasattr(source, "seek"):
        source.seek(0)
    return read_photo(source, size, "L" if grey else None)
