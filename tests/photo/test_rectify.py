"""Rectification: the four corners proposed from a photo (`facaid.photo.corners.propose_corners`), checked on photo-like
pictures of generated facades seen in perspective (`facaid.photo.photolike`), whose true corners are known."""

from __future__ import annotations

import io
import json
import time

import numpy as np
import pytest
from PIL import Image

from facaid.cli import main
from facaid.generator import generate
from facaid.photo.corners import propose_corners, propose_corners_file
from facaid.photo.photolike import facade_box, render_photo, warp
from facaid.photo.rectify import output_size, rectify

# seeds 0-11 less the `wings` facades (5, 6), whose box holds sky beside the lower wings: there the true corners
# are the box's, where the facade's lines end at the tallest wing
SEEDS = (0, 1, 2, 3, 4, 7, 8, 9, 10, 11)


def scene(seed: int, strength: float = 0.25):
    g = generate(seed)
    facade = render_photo(g.segmentation, seed).crop(facade_box(g.segmentation))
    photo, corners = warp(facade, seed, strength=strength)
    return facade, photo, np.array(corners)


def corner_error(found, true) -> float:
    """The farthest proposed corner from its true one, as a share of the facade's diagonal."""
    diag = np.hypot(*(true.max(axis=0) - true.min(axis=0)))
    return float(np.linalg.norm(np.asarray(found) - true, axis=1).max() / diag)


def test_proposed_corners_land_on_the_facade():
    errors = []
    for seed in SEEDS:
        _, photo, true = scene(seed)
        found = propose_corners(photo)
        assert 0.0 <= found["confidence"] <= 1.0
        errors.append(corner_error(found["corners"], true))
    errors = np.array(errors)
    # measured: 9 of 10 within 0.3 %, seed 2 (a narrow facade among poles and wires) 29 %
    assert (errors < 0.02).sum() >= 9, errors
    assert np.median(errors) < 0.005, errors


def test_strong_perspective_still_mostly_right():
    errors = np.array([corner_error(propose_corners(photo)["corners"], true)
                       for _, photo, true in (scene(seed, 0.4) for seed in range(100, 108))])
    # measured: 6 of 8 within 0.4 %; 104 and 106 (few vertical edges, a tree beside) far off
    assert (errors < 0.03).sum() >= 6, errors


def _box_iou(found, box) -> float:
    """IoU of the proposed quadrilateral's bounding box with a box (x0, y0, x1, y1): both upright here."""
    q = np.asarray(found)
    a = (q[:, 0].min(), q[:, 1].min(), q[:, 0].max(), q[:, 1].max())
    inter = max(0.0, min(a[2], box[2]) - max(a[0], box[0])) * max(0.0, min(a[3], box[3]) - max(a[1], box[1]))
    union = (a[2] - a[0]) * (a[3] - a[1]) + (box[2] - box[0]) * (box[3] - box[1]) - inter
    return inter / union


def test_a_rectified_photo_says_so_and_its_facade_keeps_the_wall_beyond_its_outer_windows():
    """A photo that is already a facade seen head-on (what a rectified photo or CMP's base set is): the note says
    so, and the proposal goes on past the outermost windows while the wall does (issue 57: it cut a bay or a
    floor off most rectified photos), but not past the facade onto a plain sky or street."""
    head_on, framed = [], []
    for seed in range(8):
        g = generate(seed)
        facade = render_photo(g.segmentation, seed).crop(facade_box(g.segmentation))
        w, h = facade.size
        found = propose_corners(facade)
        assert any("fronto-parallel" in note for note in found["notes"]), found["notes"]
        head_on.append(_box_iou(found["corners"], (0, 0, w, h)))
        canvas = Image.new("RGB", (w + 200, h + 160), (190, 205, 225))
        canvas.paste(facade, (100, 120))
        framed.append(_box_iou(propose_corners(canvas)["corners"], (100, 120, 100 + w, 120 + h)))
    # measured: head-on median 0.88 (0.63 to 1.0; it was 0.60 for three of them before), framed all 0.89 or more
    assert np.median(head_on) >= 0.85 and min(framed) >= 0.85, (head_on, framed)


def _difference(photo, corners, facade) -> float:
    """Mean absolute grey-level difference between the photo rectified from ``corners`` and the facade."""
    out = rectify(photo, corners, size=facade.size).convert("L")
    return float(np.abs(np.asarray(out, float) - np.asarray(facade.convert("L"), float)).mean())


def test_rectifying_with_the_proposal_gives_back_the_facade():
    for seed in (0, 7):
        facade, photo, true = scene(seed)
        w, h = photo.size
        proposed = _difference(photo, propose_corners(photo)["corners"], facade)
        exact = _difference(photo, true, facade)
        unrectified = _difference(photo, [[0, 0], [w, 0], [w, h], [0, h]], facade)
        # measured (seeds 0, 7): 6.1 and 4.0 grey levels; 2.5 and 2.2 with the true corners; 48 and 37 unrectified
        assert proposed < 10 and proposed < 0.25 * unrectified, (proposed, exact, unrectified)


def test_the_same_photo_gives_the_same_proposal():
    _, photo, _ = scene(3)
    assert propose_corners(photo) == propose_corners(photo.copy())


def test_modes_of_the_same_photo_agree():
    _, photo, true = scene(4)
    for image in (photo.convert("CMYK"), photo.convert("L"), photo.convert("RGBA"), photo.convert("P"),
                  photo.convert("I;16"), photo.convert("F")):
        found = propose_corners(image)
        assert corner_error(found["corners"], true) < 0.02, (image.mode, found)


def test_a_jpeg_file_is_read_small_and_answered_in_its_own_pixels():
    _, photo, true = scene(1)
    big = photo.resize((photo.width * 2, photo.height * 2), Image.Resampling.BICUBIC)
    buf = io.BytesIO()
    big.save(buf, "JPEG", quality=90)
    buf.seek(0)
    found = propose_corners_file(buf)
    assert corner_error(found["corners"], true * 2) < 0.01, found


@pytest.mark.parametrize("image", [
    Image.new("RGB", (1, 1)), Image.new("RGB", (640, 480), (90, 120, 150)), Image.new("L", (5000, 3)),
    Image.new("RGB", (3, 5000), (10, 10, 10)), Image.new("RGBA", (300, 200), (0, 0, 0, 0)),
    Image.new("I;16", (64, 64), 40000), Image.new("1", (400, 300)), Image.new("F", (100, 100), float("nan")),
    Image.new("LA", (50, 80)), Image.new("CMYK", (200, 100), (0, 50, 100, 0)),
], ids=["1x1", "one-colour", "wide", "tall", "transparent", "16-bit", "bilevel", "nan", "LA", "CMYK"])
def test_odd_images_get_their_own_corners_with_a_note(image):
    found = propose_corners(image)
    w, h = image.size
    assert found["corners"] == [[0, 0], [w, 0], [w, h], [0, h]]
    assert found["confidence"] == 0.0 and found["notes"]


def test_noise_and_stripes_do_not_crash():
    rng = np.random.default_rng(0)
    noise = Image.fromarray(rng.integers(0, 256, (300, 400, 3), dtype=np.uint8))
    stripes = Image.fromarray(((np.arange(400) // 7 % 2) * 255).astype(np.uint8)[None].repeat(300, 0))
    for image in (noise, stripes):
        found = propose_corners(image)
        pts = np.array(found["corners"])
        assert pts.shape == (4, 2) and (pts >= 0).all() and (pts <= [400, 300]).all()


def test_fast_on_a_1024_pixel_photo():
    _, photo, _ = scene(0)
    photo = photo.resize((1024, round(1024 * photo.height / photo.width)))
    propose_corners(photo)  # OpenCV's import
    best = min(_timed(propose_corners, photo) for _ in range(3))
    assert best < 1.0, best  # measured: 0.06 s on one core of this project's machine


def _timed(fn, *args) -> float:
    start = time.perf_counter()
    fn(*args)
    return time.perf_counter() - start


def test_cli_proposes_writes_the_json_and_rectifies(tmp_path, capsys):
    _, photo, true = scene(7)
    path = tmp_path / "photo.jpg"
    photo.save(path, quality=92)
    assert main(["rectify", str(path), "--propose", "--json", str(tmp_path / "c.json"),
                 "--out", str(tmp_path / "r.png")]) == 0
    written = json.loads((tmp_path / "c.json").read_text())
    assert corner_error(written["corners"], true) < 0.01 and (written["width"], written["height"]) == photo.size
    assert "confidence" in capsys.readouterr().out
    assert Image.open(tmp_path / "r.png").size == output_size(written["corners"])
    assert main(["rectify", str(path), "--corners", "0,0 40,0 40,30 0,30", "--out", str(tmp_path / "s.png")]) == 0
    assert Image.open(tmp_path / "s.png").size == (40, 30)


@pytest.mark.parametrize(("args", "message"), [
    (["--propose"], "cannot read"),
    ([], "give --propose"),
    (["--corners", "0,0 1,1"], "--corners: corners must be four"),
    (["--corners", "a,b"], "--corners: give four points"),
    (["--corners", "0,0 9,9 9,0 0,9"], "--corners: corners must form a convex"),
])
def test_cli_rectify_refuses_bad_input(tmp_path, capsys, args, message):
    path = tmp_path / "photo.png"
    if args != ["--propose"]:
        Image.new("RGB", (20, 20)).save(path)
    assert main(["rectify", str(path), *args]) == 2
    assert message in capsys.readouterr().err


def test_cli_rectify_refuses_a_file_that_is_no_image(tmp_path, capsys):
    (tmp_path / "x.png").write_text("not a picture")
    assert main(["rectify", str(tmp_path / "x.png"), "--propose"]) == 2
    assert "not an image" in capsys.readouterr().err


def test_the_whole_photo_as_its_own_quadrilateral_comes_back_as_it_was():
    """Pixel centres line up: the identity warp moves no pixel (OpenCV samples at whole coordinates, the corners
    are continuous ones)."""
    _, photo, _ = scene(2)
    w, h = photo.size
    out = np.asarray(rectify(photo, [[0, 0], [w, 0], [w, h], [0, h]], size=(w, h)), dtype=float)
    assert np.abs(out - np.asarray(photo.convert("RGB"), dtype=float)).max() <= 1


def test_a_large_jpeg_is_read_at_a_reduced_scale_and_rectifies_as_the_full_one():
    """A JPEG four times larger than what its rectified image needs is decoded at half its scale or less, and the
    result is the full-scale rectification within a few grey levels."""
    import io

    from facaid.photo.rectify import rectify_file

    facade, photo, true = scene(5)
    big = photo.resize((round(photo.width * 4.1) | 1, round(photo.height * 4.1) | 1), Image.Resampling.BICUBIC)
    buf = io.BytesIO()  # odd sides: the reduced decode's last pixel covers less of the photo than the others
    big.save(buf, "JPEG", quality=95)
    corners = [[x * big.width / photo.width, y * big.height / photo.height] for x, y in true]
    reduced = rectify_file(io.BytesIO(buf.getvalue()), corners, max_pixels=facade.width * facade.height)
    full = rectify(Image.open(io.BytesIO(buf.getvalue())), corners, size=reduced.size)
    diff = np.abs(np.asarray(reduced, dtype=float) - np.asarray(full, dtype=float)).mean()
    assert reduced.size == full.size and diff < 1.5, diff  # 0.68 measured (1.39 scaled by the sizes' ratio)
