"""One way to open a photo (`facaid.photo.files.open_photo`): upright as a viewer shows it, whichever command
reads it. A phone's portrait photo is stored on its side with an EXIF orientation tag."""

import io
import json

import numpy as np
import pytest
from PIL import Image

from facaid.cli import main
from facaid.generator import generate
from facaid.photo.appearance import levels
from facaid.photo.files import open_photo, read_photo, resized
from facaid.photo.photolike import render_photo

ROTATED = 6  # EXIF: the stored pixels are to be turned 90 degrees clockwise to stand upright


def stored_on_its_side(tmp_path, upright: Image.Image):
    """``upright`` written as a camera held sideways writes it: turned, with the tag that turns it back."""
    path = tmp_path / "portrait.jpg"
    exif = Image.Exif()
    exif[0x0112] = ROTATED
    upright.transpose(Image.Transpose.ROTATE_90).save(path, quality=95, exif=exif)
    return path


def test_every_reader_sees_the_photo_upright(tmp_path, capsys):
    sample = generate(3)
    upright = render_photo(sample.segmentation, 3)
    path = stored_on_its_side(tmp_path, upright)
    with Image.open(path) as raw:
        assert raw.size == (upright.height, upright.width)  # as stored
    opened = open_photo(path)
    assert opened.size == upright.size and opened.getexif().get(0x0112, 1) == 1  # turned, and the tag dropped
    diff = np.abs(np.asarray(opened, np.float32) - np.asarray(upright, np.float32)).mean()
    assert diff < 4  # the same picture, up to JPEG
    grey = open_photo(path, draft=(upright.width // 4, upright.height // 4), grey=True)
    # upright, and the smallest JPEG scale at least the size asked for, the orientation reckoned with: 1/4 here
    assert grey.mode == "L" and grey.size == ((upright.width + 3) // 4, (upright.height + 3) // 4)
    from_file, from_image = (levels(p, upright.width, upright.height).array for p in (path, upright))
    assert from_file.shape == from_image.shape and np.abs(from_file - from_image).mean() < 4
    seg = tmp_path / "seg.json"
    seg.write_text(json.dumps(sample.segmentation.to_dict()))
    out = tmp_path / "over.png"
    assert main(["render", str(seg), "--photo", str(path), "--out", str(out)]) == 0
    assert main(["complete", str(seg), "--photo", str(path)]) == 0
    capsys.readouterr()
    corners = f"0,0 {upright.width},0 {upright.width},{upright.height} 0,{upright.height}"
    rectified = tmp_path / "r.png"
    assert main(["rectify", str(path), "--corners", corners, "--out", str(rectified)]) == 0
    assert Image.open(rectified).size == upright.size


def _picture(mode: str, size=(203, 131)) -> Image.Image:
    """A smooth picture (noise upscaled: every filter shrinks it alike) with a transparent patch."""
    rng = np.random.default_rng(5)
    coarse = Image.fromarray(rng.integers(0, 256, size=(6, 9, 4), dtype=np.uint8), "RGBA")
    picture = coarse.resize(size, Image.Resampling.BICUBIC)
    picture.paste((40, 80, 160, 90), (size[0] // 4, size[1] // 4, size[0] // 2, size[1] // 2))
    return picture.convert(mode)


@pytest.mark.parametrize("fmt, mode", [("PNG", "RGBA"), ("PNG", "RGB"), ("PNG", "P"), ("WEBP", "RGBA"),
                                       ("WEBP", "RGB"), ("JPEG", "RGB"), ("JPEG", "CMYK")])
@pytest.mark.parametrize("want", ["RGB", "L"])
def test_a_photo_read_small_is_the_whole_photo_converted_and_resized(tmp_path, fmt, mode, want):
    """`read_photo` at a reduced size and mode: what decoding it whole, converting and resizing gives (the reduced
    decodes: a WebP scaled by libwebp, a JPEG at a DCT scale, a PNG converted strip by strip)."""
    path = tmp_path / f"p.{fmt.lower()}"
    _picture(mode).save(path, fmt, **({"lossless": True} if fmt == "WEBP" else {"quality": 95} if fmt == "JPEG"
                                      else {}))
    small = read_photo(path, (61, 40), want)
    assert small.mode == want and small.size == (61, 40)
    whole = Image.open(path).convert(want).resize((61, 40), Image.Resampling.BILINEAR)
    diff = np.abs(np.asarray(small, np.float32) - np.asarray(whole, np.float32))
    assert diff.mean() < 3


def test_a_png_is_converted_strip_by_strip_as_a_whole_conversion_would():
    photo = _picture("RGBA", (803, 601))
    for size in [(400, 300), (200, 75), (803, 601), (900, 700)]:
        mine = np.asarray(resized(photo, size, "RGB", strip=40 * 803), dtype=int)
        whole = np.asarray(photo.convert("RGB").resize(size, Image.Resampling.BILINEAR), dtype=int)
        assert mine.shape == whole.shape and np.abs(mine - whole).max() <= 1


@pytest.mark.parametrize("fmt", ["PNG", "WEBP"])
def test_a_turned_photo_is_read_upright_at_the_size_asked_for(tmp_path, fmt):
    upright = _picture("RGB", (120, 60))
    exif = Image.Exif()
    exif[0x0112] = ROTATED
    path = tmp_path / f"p.{fmt.lower()}"
    upright.transpose(Image.Transpose.ROTATE_90).save(path, fmt, exif=exif, **({"lossless": True} if fmt == "WEBP"
                                                                                else {}))
    small = read_photo(path, (60, 30), "RGB")
    assert small.size == (60, 30) and small.getexif().get(0x0112, 1) == 1
    expected = np.asarray(upright.resize((60, 30), Image.Resampling.BILINEAR), np.float32)
    assert np.abs(np.asarray(small, np.float32) - expected).mean() < 4


def test_a_damaged_webp_is_an_os_error(tmp_path):
    path = tmp_path / "cut.webp"
    buf = io.BytesIO()
    _picture("RGB", (300, 200)).save(buf, "WEBP", lossless=True)
    path.write_bytes(buf.getvalue()[: len(buf.getvalue()) // 2])
    with pytest.raises(OSError):
        read_photo(path, (30, 20), "RGB")
