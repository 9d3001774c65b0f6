"""Named parameters: read off the roles, set back consistently, and the CLI that does both."""

import json
import re

import numpy as np
import pytest

from facaid.cli import main
from facaid.editing.parameters import NAMES, named_parameters, normalised, set_parameter, set_parameters
from facaid.formats.cga import procedure_cga
from facaid.generator import STYLE_NAMES, generate_procedure
from facaid.grammar.execute import execute, to_segmentation
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure
from facaid.labels import LABEL_ID
from facaid.segmentation import rasterize


def _values(proc):
    return {p.name: p.value for p in named_parameters(proc)}


def _floor_rows(proc):
    """Distinct y spans of the executed leaves under floor-role nodes, counted from the picture: the rows of
    windows (window leaves whose top edges differ)."""
    tops = sorted({round(y0) for label, x0, y0, x1, y1 in execute(proc) if label == 2 and y1 - y0 > 1})
    return tops


def _built(floors=5, height=60.0):
    """A facade written by hand: attic band, a repeat of `floors` floors of 4 tiles, a ground floor."""
    tile = Node.split("x", [(Size("flt", 10), Node.leaf("facade")), (Size("abs", 20), Node.leaf("window")),
                            (Size("flt", 10), Node.leaf("facade"))], role="tile")
    floor = Node.repeat("x", 4, [(Size("flt", 40), tile)], role="floor")
    storey = Node.split("y", [(Size("flt", 45), floor), (Size("abs", 15), Node.leaf("molding", role="band"))])
    ground = Node.split("x", [(Size("flt", 70), Node.leaf("shop")), (Size("abs", 20), Node.leaf("door")),
                              (Size("flt", 70), Node.leaf("shop"))], role="ground")
    root = Node.split("y", [(Size("abs", 30), Node.leaf("cornice", role="attic")),
                            (Size("flt", floors * height), Node.repeat("y", floors, [(Size("flt", height), storey)],
                                                                      role="floors")),
                            (Size("abs", 80), ground)], role="facade")
    return Procedure(160, 30 + floors * height + 80, root)


def test_hand_written_facade_has_the_parameters_a_person_names():
    got = _values(_built())
    assert got["floors"] == 5 and got["bays"] == 4
    assert got["floor_height"] == pytest.approx(45.0)  # the floor node, without its molding band
    assert got["ground_height"] == pytest.approx(80.0) and got["attic_height"] == pytest.approx(30.0)
    assert got["tile_width"] == pytest.approx(40.0)
    assert list(got) == [n for n in NAMES if n in got]


def test_floors_five_to_six_adds_a_floor_and_keeps_the_rest():
    proc = _built()
    out = set_parameter(proc, "floors", 6)
    assert _values(out)["floors"] == 6
    assert len(_floor_rows(out)) == 6 and len(_floor_rows(proc)) == 5
    assert out.height == pytest.approx(proc.height + 60)  # one storey: floor and its molding band
    before, after = _values(proc), _values(out)
    for name in ("floor_height", "ground_height", "attic_height", "tile_width"):
        assert after[name] == pytest.approx(before[name], abs=0.01), name
    # the ground floor is where it was, counted from the bottom
    shop = [b for b in execute(out) if b[0] == 11][0]
    assert out.height - shop[2] == pytest.approx(80, abs=0.01)


def test_lengths_change_and_the_facade_grows_by_them():
    proc = _built()
    out = set_parameters(proc, {"floor_height": 55, "ground_height": 100})
    got = _values(out)
    assert got["floor_height"] == pytest.approx(55) and got["ground_height"] == pytest.approx(100)
    assert out.height == pytest.approx(proc.height + 5 * 10 + 20)
    assert got["attic_height"] == pytest.approx(30)
    wide = set_parameter(proc, "tile_width", 50)
    assert _values(wide)["tile_width"] == pytest.approx(50) and wide.width == pytest.approx(200)


def test_bays_and_size():
    proc = _built()
    out = set_parameter(proc, "bays", 6)
    assert _values(out)["bays"] == 6 and out.width == pytest.approx(240)
    assert _values(out)["tile_width"] == pytest.approx(40)
    resized = set_parameter(proc, "width", 320)
    assert resized.width == 320


def _windowed():
    """Three floors of four tiles between two 10 px margins, each tile a window unit (window over a sill) in the
    wall."""
    unit = Node.split("y", [(Size("flt", 30), Node.leaf("window")), (Size("abs", 5), Node.leaf("sill"))],
                      role="window")
    column = Node.split("y", [(Size("flt", 10), Node.leaf("facade")), (Size("abs", 35), unit),
                              (Size("flt", 15), Node.leaf("facade"))])
    tile = Node.split("x", [(Size("flt", 10), Node.leaf("facade")), (Size("abs", 20), column),
                            (Size("flt", 10), Node.leaf("facade"))], role="tile")
    row = Node.split("x", [(Size("abs", 10), Node.leaf("facade")),
                           (Size("flt", 160), Node.repeat("x", 4, [(Size("flt", 40), tile)], role="bay")),
                           (Size("abs", 10), Node.leaf("facade"))], role="floor")
    return Procedure(180, 180, Node.repeat("y", 3, [(Size("flt", 60), row)], role="floors"))


def _leaf_sizes(proc, label):
    return sorted({(round(x1 - x0, 2), round(y1 - y0, 2)) for lab, x0, y0, x1, y1 in execute(proc) if lab == label})


def test_window_size_and_margin_are_named_and_set():
    proc = _windowed()
    got = _values(proc)
    assert got["window_width"] == pytest.approx(20) and got["window_height"] == pytest.approx(35)
    assert got["margin"] == pytest.approx(10)
    wider = set_parameter(proc, "window_width", 24)
    assert _values(wider)["window_width"] == pytest.approx(24)
    assert _leaf_sizes(wider, 2) == [(24, 30)] and wider.width == pytest.approx(180 + 4 * 4)  # every window, wider
    assert _values(wider)["tile_width"] == pytest.approx(got["tile_width"] + 4)  # the tile holds it
    narrower = set_parameter(proc, "window_width", 16)  # through its column (split along y): narrower too
    assert _leaf_sizes(narrower, 2) == [(16, 30)] and narrower.width == pytest.approx(180 - 4 * 4)
    lower = set_parameter(proc, "window_height", 30)
    assert _leaf_sizes(lower, 2) == [(20, 25)] and lower.height == pytest.approx(180)  # the wall takes the 5 px
    taller = set_parameter(proc, "window_height", 45)
    assert _leaf_sizes(taller, 5) == [(20, 5)] and _leaf_sizes(taller, 2) == [(20, 40)]  # the sill keeps its 5 px
    assert taller.height == pytest.approx(180 + 3 * 10) and taller.width == proc.width
    margins = set_parameter(proc, "margin", 15)
    assert _values(margins)["margin"] == pytest.approx(15) and margins.width == pytest.approx(190)
    assert _leaf_sizes(margins, 2) == _leaf_sizes(proc, 2)  # the windows keep their size
    text = procedure_cga(wider)
    # in the CGA, each length sizes the parts whose split runs along it: the unit's height and the margins here
    assert re.search(r"^attr window_height = ", text, flags=re.M) and re.search(r"^attr margin = ", text, flags=re.M)


def test_a_margin_of_nothing_declares_no_cga_attribute():
    text = procedure_cga(set_parameter(_windowed(), "margin", 0))
    assert not re.search(r"^attr margin = ", text, flags=re.M)


@pytest.mark.parametrize("style", STYLE_NAMES)
def test_generated_facades_round_trip(style):
    for seed in range(3):
        proc = generate_procedure(seed, style)
        a, b = np.array(execute(proc)), np.array(execute(normalised(proc)))
        assert a.shape == b.shape and np.abs(a - b).max() < 0.01  # normalising changes nothing
        for p in named_parameters(proc):
            if p.name in ("width", "height") or p.min == p.max:
                continue
            # every parameter grows; the window's size shrinks too (a shorter tile or floor in a row of
            # other rows gives way to them: not checked here)
            down = p.name in ("window_width", "window_height")
            for target in ((p.value + 1,) if p.integer
                           else (p.value + 10, *((p.value - min(10, p.value / 2),) if down else ()))):
                out = set_parameter(proc, p.name, target)
                assert to_segmentation(out).rects  # executes
                if p.name not in ("bays", "margin"):  # bays in rows of other lengths change in proportion; a
                    # margin where another row has none gives way to what that row holds
                    assert _values(out)[p.name] == pytest.approx(target, abs=0.05), (style, seed, p.name, target)


def test_bad_values_name_the_problem():
    proc = _built()
    with pytest.raises(ValueError, match="unknown parameter 'storeys'"):
        set_parameter(proc, "storeys", 3)
    with pytest.raises(ValueError, match="whole number"):
        set_parameter(proc, "floors", 5.5)
    with pytest.raises(ValueError, match="from 1"):
        set_parameter(proc, "floors", 0)
    with pytest.raises(ValueError, match="must be a number"):
        set_parameter(proc, "floor_height", "tall")
    flat = Procedure(100, 100, Node.split("y", [(Size("flt", 50), Node.leaf("facade", role="floor")),
                                                (Size("flt", 50), Node.leaf("facade", role="floor"))]))
    assert _values(flat)["floors"] == 2
    side = Procedure(100, 100, Node.split("x", [(Size("flt", 50), Node.leaf("facade", role="floor")),
                                                (Size("flt", 50), Node.leaf("facade", role="floor"))]))
    with pytest.raises(ValueError, match="cannot change here"):  # floors side by side: no storey to repeat
        set_parameter(side, "floors", 3)
    with pytest.raises(ValueError, match="no 'attic_height'"):
        set_parameter(flat, "attic_height", 3)


def test_floors_laid_out_one_by_one_take_one_more():
    """A house of one floor, or of floors a split lays out one by one (the generator's, when they differ), takes a
    floor more: the floors become the repeat they are, the typical one repeated, the facade one floor higher."""
    one = Procedure(100, 150, Node.split("y", [(Size("abs", 50), Node.leaf("background")),
                                               (Size("flt", 100), Node.leaf("window", role="floor"))]))
    two = set_parameter(one, "floors", 2)
    assert _values(two)["floors"] == 2 and two.height == 250
    flat = Procedure(100, 100, Node.split("y", [(Size("flt", 40), Node.leaf("facade", role="floor")),
                                                (Size("flt", 60), Node.leaf("window", role="floor"))]))
    three = set_parameter(flat, "floors", 3)
    assert _values(three)["floors"] == 3
    labels = rasterize(to_segmentation(three))[:, 50]
    assert (labels == LABEL_ID["window"]).sum() == 120 and (labels == LABEL_ID["facade"]).sum() == 40


def test_cli_lists_and_sets(tmp_path, capsys):
    src = tmp_path / "p.json"
    src.write_text(_built().to_json())
    assert main(["params", str(src), "--json", str(tmp_path / "params.json")]) == 0
    listed = json.loads((tmp_path / "params.json").read_text())["parameters"]
    assert {p["name"]: p["value"] for p in listed}["floors"] == 5
    assert all({"name", "label", "value", "unit", "integer", "min", "max", "nodes"} <= set(p) for p in listed)
    out = tmp_path / "six.json"
    assert main(["params", str(src), "--set", "floors=6", "--out", str(out)]) == 0
    assert _values(Procedure.from_json(out.read_text()))["floors"] == 6
    capsys.readouterr()
    assert main(["params", str(src), "--set", "floors=6"]) == 2
    assert "--set needs --out" in capsys.readouterr().err
    assert main(["params", str(src), "--set", "floors=0", "--out", str(out)]) == 2
    assert "error: floors must be from 1" in capsys.readouterr().err


def test_variations_draw_named_parameters_from_ranges(tmp_path):
    from facaid.editing.variation import vary

    proc = _built()
    variants = vary(proc, 8, seed=3, ranges={"floors": (4, 7), "floor_height": (40, 50)})
    assert len(variants) == 8
    floors = [_values(v)["floors"] for v in variants]
    assert set(floors) <= {4, 5, 6, 7} and len(set(floors)) > 1
    assert all(40 <= _values(v)["floor_height"] <= 50 for v in variants)
    assert all(v.meta["variation"] == "ranges" and v.meta["parameters"]["floors"] == f
               for v, f in zip(variants, floors, strict=True))
    again = vary(proc, 8, seed=3, ranges={"floors": (4, 7), "floor_height": (40, 50)})
    assert [v.to_json() for v in again] == [v.to_json() for v in variants]  # deterministic by seed
    for ranges, message in (({"storeys": (1, 2)}, "no named parameter 'storeys'"), ({"floors": (5, 3)}, "empty"),
                            ({"floors": (0, 3)}, "leaves"), ({"floors": (2.5, 3)}, "whole numbers")):
        with pytest.raises(ValueError, match=message):
            vary(proc, 2, ranges=ranges)
    src = tmp_path / "p.json"
    src.write_text(proc.to_json())
    assert main(["vary", str(src), "--n", "3", "--range", "floors=6-6", "--out", str(tmp_path / "v")]) == 0
    written = sorted((tmp_path / "v").glob("variant-*.json"))
    assert len(written) == 3 and all(_values(Procedure.from_json(f.read_text()))["floors"] == 6 for f in written)
    with pytest.raises(SystemExit):
        main(["vary", str(src), "--range", "floors=6", "--out", str(tmp_path / "w")])


def _with_attic_tiles():
    """`_built` whose attic is a row of 2 dormer tiles of its own over the floors' 4 (the first tiles in the tree)."""
    proc = _built()
    dormer = Node.split("x", [(Size("flt", 30), Node.leaf("facade")), (Size("abs", 20), Node.leaf("window")),
                              (Size("flt", 30), Node.leaf("facade"))], role="tile")
    proc.root.children[0] = Node.repeat("x", 2, [(Size("flt", 80), dormer)], role="attic")
    return proc


def test_the_tile_width_is_the_floors_tile_and_a_bay_more_widens_by_one_of_them():
    """A newcomer saw "tile (bay) width 129 px", the attic's tile, and a bay more made the facade that much wider,
    the attic a dormer more and every floor's tile stretched."""
    proc = _with_attic_tiles()
    before = _values(proc)
    assert before["tile_width"] == pytest.approx(40.0) and before["bays"] == 4  # not the attic's 80
    out = set_parameter(proc, "bays", 5)
    after = _values(out)
    assert out.width == pytest.approx(proc.width + 40)  # one floor tile
    assert after["bays"] == 5 and after["tile_width"] == pytest.approx(40.0)
    dormers = [r for r in execute(out) if r[0] == 2 and r[2] < 30]
    assert len(dormers) == 2  # 2 x 0.5 = 1 tile: the attic keeps its dormers, wider apart
