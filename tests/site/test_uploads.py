import io
import struct
import zlib

import numpy as np
import pytest
from PIL import Image
from site_helpers import image_bytes, upload

ORIENTED = {2: Image.Transpose.FLIP_LEFT_RIGHT, 3: Image.Transpose.ROTATE_180, 4: Image.Transpose.FLIP_TOP_BOTTOM,
            5: Image.Transpose.TRANSPOSE, 6: Image.Transpose.ROTATE_90, 7: Image.Transpose.TRANSVERSE,
            8: Image.Transpose.ROTATE_270}  # the upright picture as a camera stores it for each EXIF orientation

pytestmark = pytest.mark.django_db


@pytest.mark.parametrize("fmt, ext, stored", [("JPEG", "jpg", "JPEG"), ("PNG", "png", "PNG"), ("WEBP", "webp", "JPEG")])
def test_accepted_formats(as_alice, fmt, ext, stored):
    """A WebP is stored as a JPEG (every reader reads one at a reduced scale; PIL holds a WebP four times)."""
    r = upload(as_alice, image_bytes(fmt), name=f"a.{ext}", title="front")
    assert r.status_code == 201, r.content
    body = r.json()
    assert (body["width"], body["height"]) == (64, 48) and body["visibility"] == "private"
    img = Image.open(io.BytesIO(as_alice.get(body["image"]).getvalue()))
    assert img.format == stored and img.size == (64, 48)


def stored_image(client, r) -> Image.Image:
    assert r.status_code == 201, r.content
    img = Image.open(io.BytesIO(client.get(r.json()["image"]).getvalue()))
    assert img.size == (r.json()["width"], r.json()["height"])
    return img


def picture(mode: str = "RGB", size=(90, 60)) -> Image.Image:
    """A picture whose halves differ, with a half-transparent block: turned or mirrored, it is not the same."""
    img = Image.new("RGBA", size, (200, 60, 40, 255))
    img.paste((30, 90, 210, 255), (0, 0, size[0] // 3, size[1]))
    img.paste((250, 240, 20, 128), (size[0] // 2, size[1] // 2, size[0], size[1]))
    return img.convert(mode)


def encoded(img: Image.Image, fmt: str, **save) -> bytes:
    out = io.BytesIO()
    img.save(out, fmt, **save)
    return out.getvalue()


@pytest.mark.parametrize("fmt, mode", [("JPEG", "RGB"), ("JPEG", "L"), ("PNG", "RGB"), ("PNG", "RGBA"), ("PNG", "L")])
def test_an_upright_photo_is_kept_as_sent_without_its_metadata(as_alice, fmt, mode):
    exif = Image.Exif()
    exif[0x010F], exif[0x0112] = "PhoneMaker", 1  # the camera's make; upright
    exif.get_ifd(0x8825)[2] = (48.0, 51.0, 30.0)  # GPS latitude: where it was taken
    sent = encoded(picture(mode), fmt, exif=exif.tobytes(), **({"quality": 90} if fmt == "JPEG" else {}))
    img = stored_image(as_alice, upload(as_alice, sent, name=f"a.{fmt.lower()}"))
    assert img.format == fmt and img.mode == mode
    assert np.array_equal(np.asarray(img), np.asarray(Image.open(io.BytesIO(sent))))  # not re-encoded
    assert not img.getexif() and "exif" not in img.info  # nor the camera, nor the place


@pytest.mark.parametrize("turn", range(2, 9))
def test_every_exif_orientation_is_stored_upright(as_alice, turn):
    upright = picture()
    exif = Image.Exif()
    exif[0x0112] = turn
    stored_as = upright.transpose(ORIENTED[turn])  # what a camera stores to be shown upright with ``turn``
    img = stored_image(as_alice, upload(as_alice, encoded(stored_as, "JPEG", quality=95, exif=exif.tobytes()),
                                        name="a.jpg"))
    assert img.size == upright.size and img.getexif().get(0x0112, 1) == 1
    assert np.abs(np.asarray(img, np.float32) - np.asarray(upright, np.float32)).mean() < 3


def test_a_cmyk_jpeg_is_stored_as_rgb(as_alice):
    sent = encoded(picture("CMYK"), "JPEG", quality=95)
    img = stored_image(as_alice, upload(as_alice, sent, name="a.jpg"))
    assert img.format == "JPEG" and img.mode == "RGB" and img.size == (90, 60)
    expected = np.asarray(Image.open(io.BytesIO(sent)).convert("RGB"), np.float32)
    assert np.abs(np.asarray(img, np.float32) - expected).mean() < 3


@pytest.mark.parametrize("mode, stored", [("RGB", "JPEG"), ("RGBA", "PNG")])
def test_a_webp_is_stored_as_a_jpeg_or_with_its_transparency_a_png(as_alice, mode, stored):
    exif = Image.Exif()
    exif[0x0112] = 6
    sent = encoded(picture(mode).transpose(ORIENTED[6]), "WEBP", lossless=True, exif=exif.tobytes())
    img = stored_image(as_alice, upload(as_alice, sent, name="a.webp"))
    assert img.format == stored and img.mode == mode and img.size == (90, 60)
    assert np.abs(np.asarray(img, np.float32) - np.asarray(picture(mode), np.float32)).mean() < 2


def test_a_palette_png_is_stored_in_rgb(as_alice):
    img = stored_image(as_alice, upload(as_alice, encoded(picture("P"), "PNG")))
    assert img.format == "PNG" and img.mode == "RGB"
    assert np.array_equal(np.asarray(img), np.asarray(picture("P").convert("RGB")))


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


def _animated_webp() -> bytes:
    out = io.BytesIO()
    picture().save(out, "WEBP", save_all=True, append_images=[picture("L").convert("RGB")], duration=100)
    return out.getvalue()


@pytest.mark.parametrize("data, name, message", [
    (b"", "empty.png", "empty"),
    (b"this is not an image at all", "notes.png", "not an image"),
    (b"%PDF-1.4 a document", "doc.pdf", "not an image"),
    (image_bytes("GIF"), "anim.gif", "GIF images are not accepted"),
    (image_bytes("BMP"), "bitmap.bmp", "BMP images are not accepted"),
    (image_bytes("PNG")[:60], "cut.png", "damaged or truncated"),
    (encoded(picture(size=(400, 300)), "JPEG", quality=95)[:-900], "cut.jpg", "damaged or truncated"),
    (encoded(picture(size=(400, 300)), "WEBP")[:-300], "cut.webp", "damaged or truncated"),
    (_animated_webp(), "anim.webp", "an animated WebP is not a photo"),
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
