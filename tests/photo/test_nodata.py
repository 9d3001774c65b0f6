"""No-data wedges (`facaid.photo.nodata`): the pure black corners an earlier rectification leaves are neither followed
nor taken in by the corner proposal (issue 68, item 4), checked on photo-like pictures of generated facades."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from facaid.generator import generate
from facaid.photo.corners import propose_corners
from facaid.photo.nodata import clear_of, data_edges, held, largest_clear, nodata_mask
from facaid.photo.photolike import facade_box, render_photo


def _wedged(seed: int) -> tuple[Image.Image, np.ndarray, tuple[int, int, int, int]]:
    """A generated facade head-on on a street scene, with black wedges at two of the photo's corners that cut into
    the facade's own (as an earlier rectification leaves them): the photo, its wedges, and the facade's box."""
    g = generate(seed)
    facade = render_photo(g.segmentation, seed).crop(facade_box(g.segmentation))
    w, h = facade.size
    photo = Image.new("RGB", (w + 80, h + 60), (150, 165, 185))
    photo.paste(facade, (40, 30))
    wedges = [[(0, 0), (0.4 * photo.width, 0), (0, 0.12 * photo.height)],
              [(photo.width, photo.height), (photo.width, 0.7 * photo.height), (0.88 * photo.width, photo.height)]]
    draw = ImageDraw.Draw(photo)
    mask = Image.new("1", photo.size)
    for wedge in wedges:
        draw.polygon(wedge, fill=(0, 0, 0))
        ImageDraw.Draw(mask).polygon(wedge, fill=1)
    return photo, np.asarray(mask, dtype=bool), (40, 30, 40 + w, 30 + h)


def _quad_mask(corners, size) -> np.ndarray:
    img = Image.new("1", size)
    ImageDraw.Draw(img).polygon([tuple(p) for p in corners], fill=1)
    return np.asarray(img, dtype=bool)


def test_wedges_are_found_but_not_a_dark_window_or_a_bright_sky():
    luma = np.random.default_rng(0).integers(100, 140, (200, 300)).astype(np.uint8)  # a photo's texture
    wedge = _quad_mask([(0, 0), (120, 0), (0, 70)], (300, 200))
    luma[wedge] = 0
    grey = _quad_mask([(300, 200), (300, 120), (220, 200)], (300, 200))  # some tools fill with grey
    luma[grey] = 128
    luma[90:120, 140:170] = 0  # a black window inside the photo: no edge, no wedge
    yy, xx = np.mgrid[:200, :300]
    sky = (yy < 25 + 15 * np.sin(xx / 9.0)) & (xx > 160)  # an overexposed sky with a ragged skyline
    luma[sky] = 255
    mask = nodata_mask(luma)
    assert mask[wedge].mean() > 0.95 and mask[grey].mean() > 0.9
    assert not mask[90:120, 140:170].any()
    assert not mask[sky].any()


def test_a_wedge_deep_in_the_facade_is_left_out_with_the_part_it_cuts_off_said():
    """No data is never inside a proposal (issue 68, item 4): a wedge that cuts deep into the facade takes the side
    that loses less with it, and the share it took is returned for the note."""
    mask = _quad_mask([(0, 0), (300, 0), (0, 200)], (400, 300))
    pts = np.array([[10.0, 10.0], [390.0, 10.0], [390.0, 290.0], [10.0, 290.0]])
    cleared, lost = clear_of(pts, mask)
    assert held(cleared, mask) <= 0.002
    kept = _quad_mask(cleared, (400, 300)).sum() / _quad_mask(pts, (400, 300)).sum()
    assert 0.4 < kept < 0.9 and abs((1 - lost) - kept) < 0.03, (kept, lost)


def test_clear_of_takes_the_quadrilateral_off_a_corner_wedge_and_keeps_the_rest():
    mask = _quad_mask([(0, 0), (150, 0), (0, 40)], (400, 300))  # a thin wedge along the top-left
    pts = np.array([[10.0, 10.0], [390.0, 10.0], [390.0, 290.0], [10.0, 290.0]])
    assert held(pts, mask) > 0.01
    cleared, lost = clear_of(pts, mask)
    assert held(cleared, mask) <= 0.002
    kept = _quad_mask(cleared, (400, 300)).sum() / _quad_mask(pts, (400, 300)).sum()
    assert kept > 0.85 and lost < 0.15, kept  # the top comes down by the wedge's height: the bottom stays
    assert np.allclose(cleared[2:], pts[2:], atol=3)  # within a cell or two of where they were
    assert np.allclose(clear_of(pts, np.zeros_like(mask))[0], pts)  # no wedge: nothing moves


def test_the_largest_clear_rectangle_is_found_exactly():
    rng = np.random.default_rng(3)
    for _ in range(20):
        bad = rng.random((9, 11)) < 0.25
        top, bottom, left, right = largest_clear(bad)
        assert not bad[top:bottom, left:right].any()
        best = max((b - t) * (r - l) for t in range(9) for b in range(t + 1, 10) for l in range(11)
                   for r in range(l + 1, 12) if not bad[t:b, l:r].any())
        assert (bottom - top) * (right - left) == best


def test_the_proposal_on_a_photo_with_wedges_holds_none_or_says_so_and_finds_the_facade():
    ious, deep = [], 0
    for seed in range(12):
        photo, wedges, box = _wedged(seed)
        found = propose_corners(photo)
        inside = _quad_mask(found["corners"], photo.size)
        held_share = (inside & wedges).sum() / inside.sum()
        assert held_share <= 0.005, (seed, held_share)  # never inside a proposal
        assert any("are left out" in note for note in found["notes"]), found["notes"]
        deep += any("of the facade's quadrilateral with them" in note for note in found["notes"])
        truth = _quad_mask([(box[0], box[1]), (box[2], box[1]), (box[2], box[3]), (box[0], box[3])], photo.size)
        data = ~wedges
        ious.append((inside & truth & data).sum() / ((inside | truth) & data).sum())
    # measured: every proposal clear of the wedges, 5 of 12 cut deep enough for the note to say how much went (a
    # tenth of the quadrilateral or more); IoU over the data median 0.90 (0.78 to 0.95). Before no data was never
    # inside, 10 of 12 were cleared and the other two kept 2.7 and 4 % no data, IoU median 0.94
    assert deep >= 1, deep
    assert np.median(ious) >= 0.9 and min(ious) >= 0.75, ious


def test_a_head_on_proposal_widens_to_where_the_data_ends_not_to_the_photo_edge():
    mask = np.zeros((300, 400), dtype=bool)
    mask[:, :30] = True  # a grey strip down the left
    mask[250:, 300:] = True  # a corner wedge below the right: less than half the box's width
    assert data_edges(mask, (100, 50, 300, 250)) == (30.0, 0.0, 400.0, 300.0)
    mask[:, 360:] = True
    assert data_edges(mask, (100, 50, 300, 250))[2] == 360.0


def test_a_blown_out_or_smooth_sky_above_a_straight_roofline_keeps_the_roofline():
    """A white (or smoothly graded) sky over a flat roof touches the photo's edge and is convex like a wedge; the
    roofline under it is the facade's own line: the proposal is the one the same photo with a textured sky gets (a
    review found a bay lost on each side)."""
    g = generate(0)
    facade = render_photo(g.segmentation, 0).crop(facade_box(g.segmentation))
    w, h = facade.size
    rng = np.random.default_rng(0)
    found = {}
    for sky in ("textured", "white", "gradient"):
        photo = np.full((h + 200, w + 240, 3), (150, 165, 185), np.uint8)
        photo[:] = np.clip(photo + rng.normal(0, 6, photo.shape), 0, 255).astype(np.uint8)
        if sky == "white":
            photo[:150] = 255
        elif sky == "gradient":
            photo[:150] = np.linspace(200, 235, w + 240, dtype=np.uint8)[None, :, None]
        image = Image.fromarray(photo)
        image.paste(facade, (120, 150))
        found[sky] = np.array(propose_corners(image)["corners"])
    diagonal = np.hypot(w, h)
    for sky in ("white", "gradient"):
        assert np.abs(found[sky] - found["textured"]).max() <= 0.01 * diagonal, (sky, found)
