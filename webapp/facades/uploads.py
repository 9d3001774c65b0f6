"""Checking and normalizing uploaded photos: JPEG (MPO from phones: its first frame), PNG or WebP only, size and
pixel limits, decompression bombs refused before anything is decoded, stored upright and without metadata.

Every upload is decoded first at a reduced size where the format allows (a JPEG at 1/8 of its DCT scale, a WebP
scaled by libwebp; a PNG cannot be, and decodes once), which checks that it is whole. A photo already upright in a
mode every reader takes (a JPEG in RGB or grey, a PNG in RGB, RGBA or grey) is then kept as it was sent, its
metadata dropped from the bytes (`facaid.photo.metadata`); the rest is decoded once at full size and re-encoded: a
JPEG turned by its EXIF tag, in CMYK or an MPO by OpenCV (upright and in 3 bytes a pixel as it decodes, where PIL
holds 4 and a turned copy), a WebP as a JPEG (a PNG with transparency) from libwebp's pixels, which PIL then shares,
a PNG of another mode or turned by PIL. A 40 MP photo so holds one full-size copy; `bench/bench_render_memory.py`
measures each case."""

from __future__ import annotations

import io
import warnings

import numpy as np
from django.conf import settings
from django.core.files.images import ImageFile
from PIL import Image, ImageMode, UnidentifiedImageError

from facaid.photo import metadata, webp
from facaid.photo.files import TRANSPOSE, orientation, read_photo
from webapp.facades.errors import Invalid

FORMATS = {"JPEG": "jpg", "PNG": "png", "WEBP": "webp"}
MIN_SIDE = 16  # pixels: smaller is no photo of a facade (a newcomer's 4 x 4 test image was taken)
ALIASES = {"MPO": "JPEG"}  # a phone's JPEG with more frames (a second view, depth): the first is the photo
KEPT = {"JPEG": ("RGB", "L"), "PNG": ("RGB", "RGBA", "L")}  # stored as sent when upright in these modes
JPEG_QUALITY = 92


class UploadError(Invalid, ValueError):
    """An upload we refuse; the message is shown to the user. Input at fault: the ``image``, as the API and the
    upload form name it."""

    def __init__(self, message: str, field: str = "image"):
        super().__init__(message, field)


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
    data = upload.read()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(io.BytesIO(data)) as img:  # reads the header only
                fmt = ALIASES.get(img.format, img.format)
                if fmt not in FORMATS:
                    raise UploadError(f"{fmt or 'this'} images are not accepted; upload a JPEG, PNG or WebP photo")
                _check_size(*img.size, max_pixels)
                if getattr(img, "n_frames", 1) > 1 and fmt == "WEBP":
                    raise UploadError("an animated WebP is not a photo; upload one picture")
                turn, mode, kept = orientation(img), img.mode, img.format in KEPT and img.mode in KEPT[img.format]
                stored = img.size
                _check_decodes(img, data)
                img.close()  # the decoded pixels let go before any re-encoding
            if kept and turn == 1:
                out = metadata.stripped(data, fmt)
            else:
                fmt, out = _reencoded(data, fmt, mode)
            w, h = _upright_size(stored, turn)
    except UploadError:
        raise
    except (Image.DecompressionBombError, Image.DecompressionBombWarning):
        raise UploadError("the image is too large once decompressed") from None
    except UnidentifiedImageError:
        raise UploadError("the file is not an image we can read; upload a JPEG, PNG or WebP photo") from None
    except (OSError, SyntaxError, ValueError) as exc:
        raise UploadError(f"the image is damaged or truncated ({exc})") from None
    return ImageFile(io.BytesIO(out), name=f"photo.{FORMATS[fmt]}"), w, h


def _check_size(w: int, h: int, max_pixels: int) -> None:
    if w < 1 or h < 1:
        raise UploadError("the image has no pixels")
    if min(w, h) < MIN_SIDE:
        raise UploadError(f"the image is {w}x{h} px; a facade photo needs at least {MIN_SIDE} px a side")
    if w * h > max_pixels:
        raise UploadError(f"the image is {w}x{h} ({w * h / 1e6:.0f} megapixels); at most "
                          f"{max_pixels / 1e6:.0f} megapixels are accepted")


def _check_decodes(img: Image.Image, data: bytes) -> None:
    """Decode the whole file at the smallest size its format allows (an OSError when it is damaged or cut)."""
    small = (max(1, img.width // 8), max(1, img.height // 8))
    if img.format == "WEBP":
        webp.decode(data, small)
    else:
        img.draft(img.mode if img.mode in ("RGB", "L") else None, small)  # JPEG: 1/8; a PNG decodes whole
        img.load()


def _upright_size(size: tuple[int, int], turn: int) -> tuple[int, int]:
    return (size[1], size[0]) if turn in (5, 6, 7, 8) else size


def _reencoded(data: bytes, fmt: str, mode: str) -> tuple[str, bytes]:
    """(format, bytes) of the photo upright in a mode every reader takes, decoded once at full size."""
    if fmt == "JPEG":  # turned, CMYK, an MPO: OpenCV turns it as it decodes, 3 bytes a pixel
        import cv2

        flag = cv2.IMREAD_GRAYSCALE if mode == "L" else cv2.IMREAD_COLOR
        pixels = cv2.imdecode(np.frombuffer(data, np.uint8), flag)
        if pixels is None:
            raise OSError("the JPEG does not decode")
        ok, out = cv2.imencode(".jpg", pixels, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
        if not ok:
            raise OSError("the JPEG could not be written again")
        return "JPEG", out.tobytes()
    if fmt == "WEBP":  # libwebp's pixels, shared with PIL (4 bytes a pixel: no copy)
        with Image.open(io.BytesIO(data)) as img:
            alpha = img.mode == "RGBA"
            turn = orientation(img)
        pixels = webp.decode(data, alpha=True)
        h, w = pixels.shape[:2]
        image = Image.frombuffer("RGBA" if alpha else "RGBX", (w, h), pixels, "raw", "RGBA" if alpha else "RGBX", 0, 1)
        if turn in TRANSPOSE:
            image = image.transpose(TRANSPOSE[turn])
        return _saved(image, "PNG" if alpha else "JPEG")
    target = mode if mode in KEPT["PNG"] else "RGBA" if "A" in ImageMode.getmode(mode).bands else "RGB"
    return _saved(read_photo(io.BytesIO(data), None, target), "PNG")  # another mode, or turned: rare


def _saved(image: Image.Image, fmt: str) -> tuple[str, bytes]:
    out = io.BytesIO()
    image.save(out, fmt, **({"quality": JPEG_QUALITY} if fmt == "JPEG" else {}))
    return fmt, out.getvalue()
