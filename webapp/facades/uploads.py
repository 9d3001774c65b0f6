"""Checking and normalizing uploaded photos: JPEG (MPO from phones: its first frame), PNG or WebP only, size and
pixel limits, EXIF orientation applied, decompression bombs refused before anything is decoded."""

from __future__ import annotations

import io
import warnings

from django.conf import settings
from django.core.files.images import ImageFile
from PIL import Image, ImageOps, UnidentifiedImageError

FORMATS = {"JPEG": "jpg", "PNG": "png", "WEBP": "webp"}
MIN_SIDE = 16  # pixels: smaller is no photo of a facade (a newcomer's 4 x 4 test image was taken)
ALIASES = {"MPO": "JPEG"}  # a phone's JPEG with more frames (a second view, depth): the first is the photo


class UploadError(ValueError):
    """An upload we refuse; the message is shown to the user."""


def normalize_photo(upload) -> tuple[ImageFile, int, int]:
    """Validate an uploaded file and return (file to store, width, height), oriented upright.

    Raise `UploadError` with a message for the user for anything else."""
    max_bytes, max_pixels = settings.FACAID_MAX_UPLOAD_BYTES, settings.FACAID_MAX_PIXELS
    size = getattr(upload, "size", None)
    if not size:
        raise UploadError("the file is empty")
    if size > max_bytes:
        raise UploadError(f"the file is {size / 2**20:.1f} MB; at most {max_bytes / 2**20:.0f} MB are accepted")
    upload.seek(0)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            img = Image.open(upload)  # reads the header only; decoded from the upload's own file, not a copy
            fmt = ALIASES.get(img.format, img.format)
            if fmt not in FORMATS:
                raise UploadError(f"{fmt or 'this'} images are not accepted; upload a JPEG, PNG or WebP photo")
            w, h = img.size
            if w < 1 or h < 1:
                raise UploadError("the image has no pixels")
            if min(w, h) < MIN_SIDE:
                raise UploadError(f"the image is {w}x{h} px; a facade photo needs at least {MIN_SIDE} px a side")
            if w * h > max_pixels:
                raise UploadError(f"the image is {w}x{h} ({w * h / 1e6:.0f} megapixels); at most "
                                  f"{max_pixels / 1e6:.0f} megapixels are accepted")
            img.load()
    except UploadError:
        raise
    except (Image.DecompressionBombError, Image.DecompressionBombWarning):
        raise UploadError("the image is too large once decompressed") from None
    except UnidentifiedImageError:
        raise UploadError("the file is not an image we can read; upload a JPEG, PNG or WebP photo") from None
    except (OSError, SyntaxError, ValueError) as exc:
        raise UploadError(f"the image is damaged or truncated ({exc})") from None
    ImageOps.exif_transpose(img, in_place=True)  # upright, and the orientation tag dropped; no copy
    if img.mode not in ("RGB", "RGBA", "L"):
        img = img.convert("RGBA" if "A" in img.getbands() else "RGB")
    if fmt == "JPEG" and img.mode == "RGBA":
        img = img.convert("RGB")
    out = io.BytesIO()
    save = {"JPEG": {"quality": 92}, "PNG": {"optimize": False}, "WEBP": {"quality": 92}}[fmt]
    img.save(out, fmt, **save)
    out.seek(0)
    return ImageFile(out, name=f"photo.{FORMATS[fmt]}"), img.width, img.height
