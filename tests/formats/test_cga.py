"""The CGA export, run back by a small interpreter of the CGA it writes (split with absolute, relative and floating
sizes, repeat groups, colour, NIL; y up), against the procedure's own execution."""

import re

import numpy as np
import pytest
from grammar_helpers import example, facade

from facaid.formats.cga import LEAF_RULES, default_scale, procedure_cga
from facaid.generator import generate
from facaid.grammar.execute import execute
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import Procedure
from facaid.labels import LABEL_ID, PALETTE

COLOUR_LABEL = {"#{:02x}{:02x}{:02x}".format(*rgb): name for name, rgb in PALETTE.items()}
RULE_LABEL = {rule: label for label, rule in LEAF_RULES.items()}


def parse_rules(text: str) -> dict[str, str]:
    """Each rule's body: one line, or the lines of a ``case`` rule joined by newlines."""
    rules = {name: "\n".join(line.strip() for line in body.strip("\n").split("\n"))
             for name, body in re.findall(r"^(\w+) -->\n((?:\t.*\n?)+)", text, flags=re.M)}
    assert "@StartRule\nFacade -->" in text
    return rules


def pick_case(body: str, index: int, total: int) -> str:
    """The rule a ``case split.index == i : A ... else : B`` body picks for this part of its split."""
    lines = body.split("\n")
    for condition, rule in zip(lines[::2], lines[1::2], strict=True):
        if condition == "else :":
            return rule
        found = re.fullmatch(r"case (split\.total - 1 - )?split\.index == (\d+) :", condition)
        assert found, condition
        here = total - 1 - index if found.group(1) else index
        if here == int(found.group(2)):
            return rule
    raise AssertionError(f"no case for part {index} of {total}: {body}")


def parse_group(tokens: list[str], i: int) -> tuple[tuple, int]:
    """group := '{' item ('|' item)* ('}' | '}*'); item := group | size ':' name."""
    assert tokens[i] == "{", tokens[i:i + 3]
    items, i = [], i + 1
    while True:
        if tokens[i] == "{":
            group, i = parse_group(tokens, i)
            items.append(group)
        else:
            size, colon, name = tokens[i:i + 3]
            assert colon == ":", tokens[i:i + 3]
            items.append((size, name))
            i += 3
        if tokens[i] == "|":
            i += 1
            continue
        assert tokens[i] in ("}", "}*"), tokens[i]
        return ("group", items, tokens[i] == "}*"), i + 1


def nominal(size: str, length: float) -> tuple[str, float]:
    if size.startswith("~"):
        return "float", float(size[1:])
    if size.startswith("'"):
        return "fixed", float(size[1:]) * length
    return "fixed", float(size)


def lay_out(group: tuple, length: float) -> list[tuple[object, float]]:
    """The (item, length) of a group laid out on ``length``: a repeat group repeats its items as often as their
    nominal length fits (at least once); fixed sizes are fixed, floating ones share the rest in proportion, and a
    nested repeat group takes what the fixed items beside it leave."""
    _, items, repeat = group
    if repeat:
        unit = sum(nominal(size, length)[1] for size, _ in items)
        items = items * max(1, round(length / unit))
    fixed = sum(nominal(it[0], length)[1] for it in items if it[0] != "group" and nominal(it[0], length)[0] == "fixed")
    floating = [nominal(it[0], length)[1] for it in items if it[0] != "group" and nominal(it[0], length)[0] == "float"]
    nested = [it for it in items if it[0] == "group"]
    assert not (nested and floating), "a nested repeat group beside floating items"
    share = (length - fixed) / sum(floating) if floating else 0.0
    out = []
    for it in items:
        if it[0] == "group":
            out.append((it, length - fixed))
            continue
        kind, value = nominal(it[0], length)
        out.append((it[1], value * share if kind == "float" else value))
    return out


def attributes(text: str) -> dict[str, float]:
    """The ``attr name = value`` declarations, each after its ``@Range(min=.., max=..)`` annotation."""
    found = re.findall(r"^@Range\(min=([\d.]+), max=([\d.]+)\)\nattr (\w+) = ([\d.]+)$", text, flags=re.M)
    assert len(found) == len(re.findall(r"^attr ", text, flags=re.M))
    for low, high, _, value in found:
        assert float(low) <= float(value) <= float(high)
    return {name: float(value) for _, _, name, value in found}


def run_cga(text: str, width_m: float, height_m: float, **overrides: float
            ) -> list[tuple[str, float, float, float, float]]:
    """The leaves the rules draw on a facade of this size: (label, x0, y0, x1, y1) in metres, y up; attributes
    set to their declared values or to ``overrides``."""
    rules = parse_rules(text)
    attrs = attributes(text) | overrides
    leaves = []

    def apply(name: str, box: tuple[float, float, float, float], index: int = 0, total: int = 1) -> None:
        if name in RULE_LABEL and name not in rules:
            raise AssertionError(f"label rule {name} is not written")
        body = rules[name]
        if body.startswith("case "):
            apply(pick_case(body, index, total), box, index, total)
            return
        if body == "NIL":
            return
        colour = re.fullmatch(r'color\("(#[0-9a-f]{6})"\)', body)
        if colour:
            assert RULE_LABEL[name] == COLOUR_LABEL[colour.group(1)], name
            leaves.append((COLOUR_LABEL[colour.group(1)], *box))
            return
        split = re.fullmatch(r"split\(([xy])\) (.+)", body)
        if split is None:
            apply(body, box)
            return
        tokens = re.findall(r"\}\*|[{}|:]|[~']?[\d.]+|~?\w+", split.group(2))
        tokens = [t if t.lstrip("~") not in attrs else t[:-len(t.lstrip("~"))] + str(attrs[t.lstrip("~")])
                  for t in tokens]
        group, end = parse_group(tokens, 0)
        assert end == len(tokens)
        parts: list[tuple[str, tuple[float, float, float, float]]] = []
        place(group, split.group(1), box, parts)
        for k, (item, sub) in enumerate(parts):  # split.index counts every shape of the split, groups flattened
            if (sub[2] - sub[0] if split.group(1) == "x" else sub[3] - sub[1]) > 0:
                apply(item, sub, k, len(parts))

    def place(group: tuple, axis: str, box: tuple[float, float, float, float], parts: list) -> None:
        x0, y0, x1, y1 = box
        lo, hi = (x0, x1) if axis == "x" else (y0, y1)
        pos = lo
        for item, length in lay_out(group, hi - lo):
            sub = (pos, y0, pos + length, y1) if axis == "x" else (x0, pos, x1, pos + length)
            if isinstance(item, tuple):
                place(item, axis, sub, parts)
            else:
                parts.append((item, sub))
            pos += length
        assert pos == pytest.approx(hi, abs=1e-3)

    apply("Facade", (0.0, 0.0, width_m, height_m))
    return leaves


def assert_same_leaves(proc: Procedure, text: str, scale: float, tol: float = 0.05) -> None:
    """The CGA's leaves, in pixels with y down, are the procedure's non-empty leaves (background aside)."""
    ours = np.array([leaf for leaf in execute(proc)
                     if leaf[0] != LABEL_ID["background"] and leaf[3] - leaf[1] > 1e-6 and leaf[4] - leaf[2] > 1e-6])
    drawn = [(LABEL_ID[label], x0 / scale, proc.height - y1 / scale, x1 / scale, proc.height - y0 / scale)
             for label, x0, y0, x1, y1 in run_cga(text, proc.width * scale, proc.height * scale)]
    theirs = np.array([leaf for leaf in drawn if leaf[3] - leaf[1] > tol and leaf[4] - leaf[2] > tol])
    ours = ours[(ours[:, 3] - ours[:, 1] > tol) & (ours[:, 4] - ours[:, 2] > tol)]
    assert len(ours) == len(theirs)
    free = np.ones(len(theirs), dtype=bool)
    for leaf in ours:
        match = free & (theirs[:, 0] == leaf[0]) & (np.abs(theirs[:, 1:] - leaf[1:]).max(axis=1) < tol)
        assert match.any(), f"no drawn rectangle matches {leaf}"
        free[np.argmax(match)] = False


@pytest.mark.parametrize("seed", [1, 3, 5, 8, 13, 21, 34, 55])
def test_the_rules_draw_the_generated_procedures(seed):
    proc = generate(seed).procedure
    scale = default_scale(proc)
    assert_same_leaves(proc, procedure_cga(proc), scale)


def hand_made() -> Procedure:
    """Reflected halves of asymmetric splits along both axes, a repeat with a tail of pillars, relative sizes."""
    door = Node.split("x", [(Size("abs", 14), Node.leaf("door")), (Size("flt", 1), Node.leaf("window"))])
    shops = Node.mirror("x", [(Size("abs", 30), Node.leaf("shop")), (Size("flt", 1), door),
                              (Size("abs", 40), Node.leaf("deco"))], center=False)
    tile = Node.split("y", [(Size("rel", 0.2), Node.leaf("cornice")), (Size("flt", 1), Node.leaf("window")),
                            (Size("abs", 6), Node.leaf("sill"))])
    bays = Node.repeat("x", 4, [(Size("abs", 8), Node.leaf("pillar")), (Size("flt", 50), tile)], tail=1)
    band = Node.mirror("y", [(Size("abs", 10), Node.leaf("molding")),
                             (Size("flt", 1), Node.split("y", [(Size("abs", 5), Node.leaf("balcony")),
                                                               (Size("flt", 1), bays)]))], center=False)
    root = Node.split("y", [(Size("abs", 20), Node.leaf("background")), (Size("flt", 2), band),
                            (Size("flt", 1), shops)])
    return Procedure(width=400, height=500, root=root)


def test_mirrors_repeats_with_tails_and_relative_sizes():
    proc = hand_made()
    text = procedure_cga(proc, scale=0.025, name="hand made")
    assert "_mx" in text and "_my" in text  # the reflected halves have rules of their own
    assert "}*" in text and "'0.2" in text
    assert "hand made" in text and "0.025 m per pixel" in text
    assert_same_leaves(proc, text, 0.025)


def test_the_wrong_mirror_fails_the_check():
    """The oracle can tell: the reflected half's rules laid out forwards draw another facade."""
    proc = hand_made()
    text = procedure_cga(proc, scale=0.025)
    broken = re.sub(r"^(\w+)_mx -->\n\t(.+)$", lambda m: f"{m.group(1)}_mx -->\n\t{m.group(1)}", text, flags=re.M)
    assert broken != text
    with pytest.raises(AssertionError):
        assert_same_leaves(proc, broken, 0.025)


def test_repeats_lay_out_as_many_copies_as_fit_on_a_wider_facade():
    proc = hand_made()
    text = procedure_cga(proc, scale=0.025)
    wide = run_cga(text, 400 * 0.025 * 1.5, 500 * 0.025)
    narrow = run_cga(text, 400 * 0.025, 500 * 0.025)
    count = {name: sum(1 for leaf in leaves if leaf[0] == "pillar") for name, leaves in (("wide", wide),
                                                                                         ("narrow", narrow))}
    assert count["narrow"] == 5 * 2 and count["wide"] > count["narrow"]  # 4 bays and a tail, in both halves


def test_the_default_scale_makes_a_storey_three_metres():
    proc = generate(3).procedure
    floors = [node for _, node in proc.nodes() if node.role == "floor"]
    assert floors
    scale = default_scale(proc)
    from facaid.grammar.execute import first_boxes
    boxes = first_boxes(proc)
    heights = sorted(boxes[id(n)][3] - boxes[id(n)][1] for n in floors)
    assert heights[len(heights) // 2] * scale == pytest.approx(3.0)
    flat = Procedure(width=300, height=600, root=Node.leaf("facade"))
    assert default_scale(flat) == pytest.approx(12.0 / 600)
    assert "Facade -->\n\tWall" in procedure_cga(flat)


def test_without_believable_floors_the_rows_of_windows_set_the_scale():
    """Four storeys of 100 px, each a window (split by a transom) over a 20 px band that an induced procedure might
    call ``floor``: the window rows' period, 100 px, is the storey."""
    window = Node.split("y", [(Size("abs", 30), Node.leaf("window")), (Size("abs", 4), Node.leaf("molding")),
                              (Size("abs", 26), Node.leaf("window"))])
    tile = Node.split("x", [(Size("flt", 1), Node.leaf("facade")), (Size("abs", 40), window),
                            (Size("flt", 1), Node.leaf("facade"))])
    storey = Node.split("y", [(Size("abs", 20), Node.leaf("facade")), (Size("abs", 60), tile),
                              (Size("abs", 20), Node.leaf("cornice", role="floor"))])
    proc = Procedure(width=200, height=400, root=Node.repeat("y", 4, [(Size("flt", 1), storey)]))
    assert default_scale(proc) == pytest.approx(3.0 / 100)
    assert_same_leaves(proc, procedure_cga(proc), 3.0 / 100)


@pytest.mark.parametrize("bad", [0, -1, float("nan"), float("inf"), 1e6, "1"])
def test_a_bad_scale_is_refused(bad):
    with pytest.raises(ValueError, match="scale must be a number of metres per pixel > 0 and at most 100"):
        procedure_cga(hand_made(), scale=bad)


def test_a_name_cannot_break_out_of_the_header_comment():
    text = procedure_cga(hand_made(), scale=0.025, name="x */ Facade -->\n\tNIL /* y")
    assert text.count("*/") == 1 and "x * / Facade --> NIL /* y" in text
    assert_same_leaves(hand_made(), text, 0.025)


def test_cli_writes_the_rules(tmp_path, capsys):
    from facaid.cli import main

    proc = hand_made()
    path = tmp_path / "p.json"
    path.write_text(proc.to_json())
    assert main(["cga", str(path), "--out", str(tmp_path / "p.cga"), "--metres-per-pixel", "0.025"]) == 0
    assert "10.00 m x 12.50 m" in capsys.readouterr().out
    assert_same_leaves(proc, (tmp_path / "p.cga").read_text(), 0.025)
    assert main(["cga", str(path), "--out", str(tmp_path / "q.cga")]) == 0
    assert (tmp_path / "q.cga").read_text() == procedure_cga(proc, name="p.json")
    assert main(["cga", str(path), "--out", str(tmp_path / "r.cga"), "--metres-per-pixel", "0"]) == 2
    assert "scale must be a number of metres per pixel" in capsys.readouterr().err
    path.write_text('{"root": 5}')
    assert main(["cga", str(path), "--out", str(tmp_path / "s.cga")]) == 2


def test_named_lengths_are_attributes_with_ranges_and_steer_the_rules():
    """The named parameters' lengths are declared as @Range attrs, the parts they stand for are sized by them,
    and setting one (as a CityEngine user does in the inspector) changes those parts' metres."""
    proc = generate(3).procedure
    scale = default_scale(proc)
    text = procedure_cga(proc)
    attrs = attributes(text)
    assert {"floor_height", "tile_width"} <= set(attrs)
    assert attrs["floor_height"] == pytest.approx(3.0, abs=0.01)  # the default scale: a storey 3 m tall
    assert re.search(r"\b~?floor_height : \w+", text) and re.search(r"\b~?tile_width : \w+", text)
    assert_same_leaves(proc, text, scale)  # at the declared values the rules draw the procedure
    w, h = proc.width * scale, proc.height * scale
    windows = [leaf for leaf in run_cga(text, w, h) if leaf[0] == "window"]
    wider = [leaf for leaf in run_cga(text, w, h, tile_width=attrs["tile_width"] * 1.3) if leaf[0] == "window"]
    assert len(wider) <= len(windows) and wider != windows


def test_no_part_of_a_split_is_under_a_centimetre():
    root = Node.split("x", [(Size("abs", 0.2), Node.leaf("pillar")), (Size("flt", 50), Node.leaf("window")),
                            (Size("abs", 49.8), Node.leaf("facade"))])
    proc = Procedure(100, 100, Node.split("y", [(Size("flt", 1), root)]))
    text = procedure_cga(proc, scale=0.02)  # the pillar is 4 mm
    assert "Pillar" not in parse_rules(text).values() and ": Pillar" not in text
    parts = [float(m) for m in re.findall(r"([\d.]+) : ", text)]
    assert parts and min(parts) >= 0.01
    drawn = run_cga(text, 2.0, 2.0)
    window = [leaf for leaf in drawn if leaf[0] == "window"][0]
    assert window[1] == pytest.approx(0.0) and window[3] == pytest.approx(1.004, abs=1e-3)  # it took the 4 mm


def test_exceptions_become_variants_picked_by_split_index():
    """A repeat whose copies differ by a node keeps its repeat split and picks each copy's rule by
    ``split.index`` (counted from the top along y, where CGA's y goes up); copies that differ in size are written
    out; either way the rules draw the procedure's rectangles, and the wrong pick fails the check."""
    deep = facade([Override(1, (0, 3, 1, 1), node=Node.leaf("blind")), Override(0, (0, 4), node=Node.leaf("door"))],
                  bays=[Override(2, (0, 1, 0), node=Node.leaf("deco"))])
    text = procedure_cga(deep, scale=0.02)
    assert "case split.total - 1 - split.index == 1 :" in text and "case split.index == 3 :" in text
    assert "}*" in text and "_v1" in text
    assert_same_leaves(deep, text, 0.02)
    broken = text.replace("split.index == 3 :", "split.index == 2 :")
    with pytest.raises(AssertionError):
        assert_same_leaves(deep, broken, 0.02)
    sized = example()
    assert_same_leaves(sized, procedure_cga(sized, scale=0.02), 0.02)


def test_the_header_says_the_size_the_3d_exports_have():
    """Issue 67: the CGA header said 24.5174 m where the glTF said 24.5053 m for one procedure, the header from the
    procedure's width in pixels unrounded, the glTF (and IFC, CityJSON) from the whole pixels it draws. One extent."""
    import json as _json

    from facaid.formats.gltf import procedure_gltf

    proc = generate(3).procedure
    proc.width, proc.height = proc.width + 0.4, proc.height - 0.3  # a sized procedure's extent is not whole pixels
    header = re.search(r"Drawn at (\d+) x (\d+) px, ([\d.]+) m x ([\d.]+) m at ([\d.]+) m per pixel", procedure_cga(
        proc, 0.0199321))
    about = _json.loads(procedure_gltf(proc, 0.0199321, binary=False))["asset"]["extras"]["facaid"]
    assert (float(header[3]), float(header[4])) == (about["width_m"], about["height_m"])
    assert (int(header[1]), int(header[2])) == (round(proc.width), round(proc.height))
