"""Opening a photo the one way every reader of photos does: as a viewer shows it."""

from __future__ import annotations

from typing import Any

from PIL import Image, ImageOps

ORIENTATION = 0x0112  # the EXIF tag


def open_photo(source: Any, draft: tuple[int, int] | None = None, grey: bool = False) -> Image.Image:
    """The photo at ``source`` (a path or a binary file) as a viewer shows it: its EXIF orientation applied (a
    phone's portrait photo stands upright; the tag is dropped), decoded now. With ``draft``, a JPEG is decoded at
    the smallest of its reduced scales (1/2, 1/4, 1/8) that is still at least that size both ways; ``grey`` decodes
    it as grey levels. PIL's errors (OSError, `Image.DecompressionBombError`) pass through."""
    with Image.open(source) as raw:
        if draft is not None:  # in the stored pixels' axes: an orientation of 5 to 8 turns the picture a quarter
            turned = raw.getexif().get(ORIENTATION, 1) in (5, 6, 7, 8)
            raw.draft("L" if grey else "RGB", draft[::-1] if turned else draft)
        image = ImageOps.exif_transpose(raw)
        if grey and image.mode != "L":
            image = image.convert("L")
        image.load()
    return image
