"""The photo's repeats (`photo.repeats`): find copies of a drawn unit (`completion.copies`) and completion's repeats, on
pictures made here: a wall with a lattice of windows under a lighting gradient, with noise and closed blinds."""

import json

import pytest
from photo_helpers import CLOSED, GRID, lattice_photo, sill_of
from PIL import Image

from facaid.completion import complete
from facaid.completion.copies import UnitError, find_copies
from facaid.labels import FACADE, LABEL_ID
from facaid.segmentation import Rect, Segmentation

WINDOW, SILL = LABEL_ID["window"], LABEL_ID["sill"]


def _near(p, box, tol=2):
    return max(abs(p[k] - v) for k, v in zip(("x0", "y0", "x1", "y1"), box, strict=True)) <= tol


def test_find_copies_carries_a_window_and_its_sill_to_every_copy_under_a_lighting_gradient():
    seg = Segmentation(700, 520, (Rect(FACADE, 0, 0, 700, 520), Rect(WINDOW, *GRID[7]), Rect(SILL, *sill_of(GRID[7]))))
    out = find_copies(seg, lattice_photo(), [1, 2])
    windows = [p for p in out if p["label"] == "window"]
    expected = [b for k, b in enumerate(GRID) if k != 7 and k not in CLOSED]
    for box in expected:  # every open window is found, in place, with its sill under it, one copy
        (w,) = [p for p in windows if _near(p, box)]
        (s,) = [p for p in out if p["label"] == "sill" and p["copy"] == w["copy"]]
        assert _near(s, sill_of(box)) and w["score"] == s["score"] >= 0.6 and w["reason"] == "copy of the unit"
    assert len(windows) == len(expected)  # nothing on the wall, nor on a closed blind
    assert [p["score"] for p in out] == sorted((p["score"] for p in out), reverse=True)  # the best copy first
    assert sorted({p["copy"] for p in out}) == list(range(len(expected)))


def test_find_copies_of_a_unit_leaves_out_what_is_drawn_rejected_or_below_the_score_asked_for():
    drawn = [Rect(WINDOW, *b) for b in GRID[:6]]  # the first row drawn
    seg = Segmentation(700, 520, (Rect(FACADE, 0, 0, 700, 520), *drawn))
    out = find_copies(seg, lattice_photo(), [3])
    assert not any(p["y0"] < 120 for p in out)  # the drawn row is not proposed again
    rejected = [{k: out[0][k] for k in ("label", "x0", "y0", "x1", "y1")}]
    again = find_copies(seg, lattice_photo(), [3], rejected=rejected)
    assert len(again) == len(out) - 1 and not any(_near(p, (out[0]["x0"], out[0]["y0"], out[0]["x1"], out[0]["y1"]))
                                                  for p in again)
    assert find_copies(seg, lattice_photo(), [3], min_score=1.0) == []
    # a photo with nothing to see (a flat render) finds nothing
    assert find_copies(seg, Image.new("L", (700, 520), 128), [3]) == []


def test_find_copies_finds_the_other_window_of_a_pair_that_nearly_touches_it():
    """Windows in pairs, 12 px apart (their frames almost touch): the other window of the selected one's pair is
    nearer than the patch with its context is wide. It was never voted for (issue 68: a window beside the selected
    one on b0212 and b0070 was missed), nor was a shift that the clustered repeats rounded off."""
    pairs = [(x + dx, y, x + dx + 50, y + 80) for y in (60, 220, 380) for x in (60, 270, 480) for dx in (0, 62)]
    photo = lattice_photo(grid=pairs, closed=())
    selected = pairs[8]  # the left window of the middle row's middle pair
    seg = Segmentation(700, 520, (Rect(FACADE, 0, 0, 700, 520), Rect(WINDOW, *selected)))
    windows = [p for p in find_copies(seg, photo, [1]) if p["label"] == "window"]
    for box in pairs:
        if box != selected:
            assert any(_near(p, box) for p in windows), (box, windows)


@pytest.mark.parametrize("unit, message", [([], "non-empty"), ("1", "non-empty"), ([9], "from 0 to 6"),
                                           ([1, 1], "distinct"), ([True], "distinct"), ([0], "not the wall"),
                                           (list(range(51)), "at most 50")])
def test_a_bad_unit_is_refused_naming_the_problem(unit, message):
    seg = Segmentation(700, 520, (Rect(FACADE, 0, 0, 700, 520), *[Rect(WINDOW, *b) for b in GRID[:6]]))
    with pytest.raises(UnitError, match=message):
        find_copies(seg, lattice_photo(), unit)


def test_completion_carries_the_drawn_elements_along_the_photos_repeats(monkeypatch):
    """Two windows and their sills drawn in a row and one in the next, on a photo where reflections make every
    window look a little different: the search for look-alikes anywhere (NCC 0.93) finds few of them, the photo's
    repeats carry the drawn ones along the drawn row and column to all of them, and not onto a closed blind."""
    from facaid.completion import propose

    drawn = [GRID[0], GRID[1], GRID[6]]
    rects = [Rect(FACADE, 0, 0, 700, 520), *(Rect(WINDOW, *b) for b in drawn)]
    rects += [Rect(SILL, *sill_of(b)) for b in drawn]
    seg = Segmentation(700, 520, tuple(rects))
    photo = lattice_photo(reflections=True)
    windows = [p for p in complete(seg, photo) if p["label"] == "window"]
    row_and_column = [GRID[k] for k in (2, 3, 4, 5, 12, 18)]  # in the drawn row (0) or column (0), not drawn
    assert all(any(_near(p, b) for p in windows) for b in row_and_column), windows
    assert not any(_near(p, GRID[k]) for p in windows for k in CLOSED)
    assert all(p["score"] >= 0.85 for p in windows if p["reason"] == "repeat of window")
    monkeypatch.setattr(propose, "REPEATS", False)
    without = [p for p in complete(seg, photo) if p["label"] == "window"]
    assert len(without) < len(windows) - 3 and not any(p["reason"].startswith("repeat") for p in without)


def test_cli_complete_with_a_unit_proposes_its_copies(tmp_path, capsys):
    from facaid.cli import main

    seg = Segmentation(700, 520, (Rect(FACADE, 0, 0, 700, 520), Rect(WINDOW, *GRID[7]), Rect(SILL, *sill_of(GRID[7]))))
    path, photo, out = tmp_path / "drawn.json", tmp_path / "photo.png", tmp_path / "copies.json"
    path.write_text(seg.to_json())
    lattice_photo().save(photo)
    assert main(["complete", str(path), "--photo", str(photo), "--unit", "1,2", "--json", str(out)]) == 0
    assert "42 proposals for 3 drawn rectangles: 21 sill, 21 window" in capsys.readouterr().out
    assert {p["copy"] for p in json.loads(out.read_text())["proposals"]} == set(range(21))
    for args, says in ((["--unit", "1,2"], "give --photo too"),
                       (["--photo", str(photo), "--unit", "0"], "not the wall"),
                       (["--photo", str(photo), "--unit", "one"], "--unit: invalid literal")):
        assert main(["complete", str(path), *args]) == 2
        assert says in capsys.readouterr().err
