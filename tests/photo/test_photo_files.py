"""One way to open a photo (`facaid.photo.files.open_photo`): upright as a viewer shows it, whichever command
reads it. A phone's portrait photo is stored on its side with an EXIF orientation tag."""

import json

import numpy as np
from PIL import Image

from facaid.cli import main
from facaid.generator import generate
from facaid.photo.appearance import levels
from facaid.photo.files import open_photo
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
