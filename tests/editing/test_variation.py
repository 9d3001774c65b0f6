import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from facaid.cli import main
from facaid.editing.parameters import named_parameters
from facaid.editing.resizing import resize
from facaid.editing.variation import change_count, swap, vary, with_count, with_size
from facaid.generator import STYLE_NAMES, generate_procedure
from facaid.grammar import Procedure, ProcedureError, execute, validate
from facaid.labels import LABEL_ID, LABELS


def windows(proc):
    return sum(1 for lab, *_ in execute(proc) if LABELS[lab] == "window")


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32), st.sampled_from(STYLE_NAMES), st.integers(0, 1000))
def test_variants_are_valid_and_deterministic(seed, style, vseed):
    proc = generate_procedure(seed, style)
    a = vary(proc, 6, vseed)
    b = vary(proc, 6, vseed)
    assert [v.to_json() for v in a] == [v.to_json() for v in b]
    for v in a:
        validate(v)
    assert {v.meta["variation"] for v in a} >= {"resize", "count"}
    for v in a:  # each says its counts, as its caption does
        counts = {p.name: p.value for p in named_parameters(v) if p.name in ("floors", "bays")}
        assert v.meta["counts"] == counts and counts
    assert proc.to_json() == generate_procedure(seed, style).to_json()  # the input is untouched


def test_resize_adapts_repeats():
    proc = generate_procedure(4, "modernist")
    wider = resize(proc, proc.width * 2, proc.height)
    assert windows(wider) > 1.6 * windows(proc)
    with pytest.raises(ValueError, match="between 1 and 16384"):
        resize(proc, 0, 10)


def test_resize_counts_the_copies_that_fit_beside_the_tail():
    """Bays of a 40 px pillar and a 40 px tile, twice, and a closing pillar (200 px). At 340 px, four bays and the
    pillar need 360 px (tiles 35 px) and three 280 px (tiles 60 px): four fit best. Counting the old region over the
    old count (100 px a bay, the tail shared out) gave three."""
    from facaid.grammar.execute import execute
    from facaid.grammar.nodes import Node, Size
    from facaid.grammar.procedure import Procedure

    bays = Node.repeat("x", 2, [(Size("abs", 40), Node.leaf("pillar")), (Size("flt", 1), Node.leaf("window"))],
                       tail=1)
    proc = Procedure(width=200, height=50, root=bays)
    wider = resize(proc, 340, 50)
    assert wider.root.count == 4
    tiles = [x1 - x0 for label, x0, _, x1, _ in execute(wider) if label == LABEL_ID["window"]]
    assert tiles == pytest.approx([35.0] * 4)
    assert resize(proc, 200, 50).root.count == 2


def test_change_count_grows_the_image():
    proc = generate_procedure(4, "modernist")
    path = next(p for p, n in proc.nodes() if n.rule == "repeat" and n.axis == "y")
    taller = change_count(proc, path, 2)
    assert taller.height > proc.height
    with pytest.raises(ProcedureError, match="not a repeat"):
        change_count(proc, "root", 1)


def test_swap_replaces_a_tile():
    proc = generate_procedure(9, "tenement")
    out = swap(proc, "tile", random.Random(3), "tenement")
    validate(out)
    with pytest.raises(ValueError, match="no node with role"):
        swap(proc, "no-such-role", random.Random(0))


def test_parameter_edits():
    proc = generate_procedure(2)
    path = next(p for p, n in proc.nodes() if n.sizes and n.sizes[0].mode == "abs")
    edited = with_size(proc, path, 0, 33.0)
    assert edited.parameters() != proc.parameters()
    with pytest.raises(ProcedureError, match="negative"):
        with_size(proc, path, 0, -1.0)
    with pytest.raises(ProcedureError, match="no size 99"):
        with_size(proc, path, 99, 1.0)
    with pytest.raises(ProcedureError, match="no such node"):
        with_size(proc, "root/9/9/9", 0, 1.0)
    rep = next(p for p, n in proc.nodes() if n.rule == "repeat")
    assert with_count(proc, rep, 3).to_dict() != proc.to_dict()


def test_cli_vary(tmp_path, capsys):
    src = tmp_path / "p.json"
    src.write_text(generate_procedure(5).to_json())
    assert main(["vary", str(src), "--n", "4", "--seed", "2", "--out", str(tmp_path / "v")]) == 0
    assert sorted(p.name for p in (tmp_path / "v").iterdir()) == [
        "variant-00.json", "variant-01.json", "variant-02.json", "variant-03.json", "variants.png"]
    for i in range(4):
        Procedure.from_json((tmp_path / "v" / f"variant-0{i}.json").read_text())


@settings(max_examples=12, deadline=None)
@given(st.integers(0, 2**32), st.sampled_from(STYLE_NAMES), st.integers(0, 1000),
       st.sampled_from([("floors",), ("bays",), ("floors", "bays")]))
def test_held_counts_stay_as_they_are(seed, style, vseed, hold):
    """A held count (its edits are not clean, say) is the same in every variant: no repeat that lays it out is
    recounted, and the facade is not resized along its axis; the other kinds still vary."""
    proc = generate_procedure(seed, style)
    before = {p.name: p.value for p in named_parameters(proc)}
    try:
        variants = vary(proc, 6, vseed, hold=hold)
    except ValueError as exc:  # nothing else to vary: said so
        assert "nothing to vary" in str(exc)
        return
    for v in variants:
        after = {p.name: p.value for p in named_parameters(v)}
        for name in hold:
            if name in before:
                assert after.get(name) == before[name], (name, v.meta["variation"])
        if v.meta["variation"] == "resize":  # not along a held count's axis, which would recount it
            assert ("floors" not in hold or v.height == proc.height) and ("bays" not in hold or v.width == proc.width)
    assert [v.to_json() for v in vary(proc, 6, vseed, hold=())] == [v.to_json() for v in vary(proc, 6, vseed)]


def test_only_counts_can_be_held():
    with pytest.raises(ValueError, match="only the counts floors and bays"):
        vary(generate_procedure(1, STYLE_NAMES[0]), 2, 0, hold=("floor_height",))
