import io
import struct
import zlib

import pytest
from PIL import Image
from site_helpers import image_bytes, upload

pytestmark = pytest.mark.django_db


@pytest.mark.parametrize("fmt, ext", [("JPEG", "jpg"), ("PNG", "png"), ("WEBP", "webp")])
def test_accepted_formats(as_alice, fmt, ext):
    r = upload(as_alice, image_bytes(fmt), name=f"a.{ext}", title="front")
    assert r.status_code == 201, r.content
    body = r.json()
    assert (body["width"], body["height"]) == (64, 48) and body["visibility"] == "private"
    img = Image.open(io.BytesIO(as_alice.get(body["image"]).getvalue()))
    assert img.format == fmt and img.size == (64, 48)


def test_exif_orientation_is_applied(as_alice):
    exif = Image.Exif()
    exif[0x0112] = 6  # rotate 90 degrees clockwise to display
    r = upload(as_alice, image_bytes("JPEG", size=(80, 40), exif=exif.tobytes()), name="a.jpg")
    assert r.status_code == 201, r.content
    assert (r.json()["width"], r.json()["height"]) == (40, 80)


def _png_header_only(width: int, height: int) -> bytes:
    """A small PNG file that claims a huge size: a decompression bomb for a naive reader."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 100)) + \
        chunk(b"IEND", b"")


@pytest.mark.parametrize("data, name, message", [
    (b"", "empty.png", "empty"),
    (b"this is not an image at all", "notes.png", "not an image"),
    (b"%PDF-1.4 a document", "doc.pdf", "not an image"),
    (image_bytes("GIF"), "anim.gif", "GIF images are not accepted"),
    (image_bytes("BMP"), "bitmap.bmp", "BMP images are not accepted"),
    (image_bytes("PNG")[:60], "cut.png", "damaged or truncated"),
    (_png_header_only(100_000, 100_000), "bomb.png", "too large"),
    (_png_header_only(8_000, 6_000), "big.png", "48 megapixels"),
    (image_bytes("PNG", size=(4, 4)), "tiny.png", "the image is 4x4 px; a facade photo needs at least 16 px a side"),
])
def test_bad_uploads_are_refused_with_a_message(as_alice, data, name, message):
    r = upload(as_alice, data, name=name)
    assert r.status_code == 400
    assert message in str(r.json()), r.json()
    assert as_alice.get("/api/v1/photos/").json()["count"] == 0  # nothing stored


def test_size_and_pixel_limits(as_alice, settings):
    settings.FACAID_MAX_UPLOAD_BYTES = 1000
    r = upload(as_alice, image_bytes("PNG", size=(300, 300), color=None) + b"\0" * 2000)
    assert r.status_code == 400 and "at most" in r.json()["image"]
    settings.FACAID_MAX_UPLOAD_BYTES = 20 * 2**20
    settings.FACAID_MAX_PIXELS = 1000
    r = upload(as_alice, image_bytes("PNG", size=(64, 48)))
    assert r.status_code == 400 and "megapixels" in r.json()["image"]


def test_upload_needs_a_login(as_charlie):
    assert upload(as_charlie, image_bytes()).status_code in (401, 403)
