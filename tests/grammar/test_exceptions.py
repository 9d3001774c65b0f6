"""Repeats that allow exceptions: a copy that differs from its siblings by a delta (its size, or one node of it
replaced) stays a copy of the repeat. Checked against the plain split the same facade is written as, in the C
executor against the Python one, the torch executor against both, and JSON against its schema."""

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import torch
from grammar_helpers import example, facade, leaf, plain_facade, random_exceptions, tile

import facaid.grammar as grammar_pkg
from facaid.editing.parameters import named_parameters, normalised, set_parameter
from facaid.generator import generate_procedure
from facaid.grammar.differentiable import compile_plan, execute_plan
from facaid.grammar.execute import execute, first_boxes, flat_rows, leaf_array
from facaid.grammar.layout import count_leaves
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import Procedure, ProcedureError, validate
from facaid.grammar.repeats import copies_moved, most_typical, recount
from facaid.labels import LABEL_ID
from facaid.native import rects
from facaid.segmentation import flatten_array_numpy, rasterize, region_boxes
from facaid.tokenizer import Tokenizer

needs_c = pytest.mark.skipif(rects.library() is None, reason="no C compiler to build the rectangles library")


def label_map(proc: Procedure) -> np.ndarray:
    from facaid.grammar.execute import to_segmentation
    return rasterize(to_segmentation(proc))


def test_a_repeat_with_exceptions_draws_the_facade_written_out():
    assert np.array_equal(label_map(example()), label_map(plain_facade()))
    assert not np.array_equal(label_map(example()), label_map(facade([])))


def test_json_round_trip_and_schema():
    jsonschema = pytest.importorskip("jsonschema")
    proc = example()
    text = proc.to_json()
    again = Procedure.from_json(text)
    assert again.to_json() == text
    assert again.root.children[1].exceptions[0] == Override(1, (0, 3, 1, 1), None, leaf("blind"))
    schema = json.loads((Path(grammar_pkg.__file__).parent / "procedure.schema.json").read_text())
    jsonschema.validate(json.loads(text), schema)
    bad = json.loads(text)
    bad["root"]["children"][1]["exceptions"][0].pop("node")
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)
    with pytest.raises(ProcedureError, match="changes nothing"):
        Procedure.from_dict(bad)


def _mutated(change) -> dict:
    obj = example().to_dict()
    change(obj["root"]["children"][1]["exceptions"])
    return obj


@pytest.mark.parametrize(("change", "message"), [
    (lambda e: e[0].update(copy=5), r"copy must be a copy of the repeat, 0 to 4"),
    (lambda e: e[0].update(copy=True), r"copy must be a copy"),
    (lambda e: e[0].update(path=[]), r"path must be a list of 1 to 32 indices"),
    (lambda e: e[0].update(path=[1]), r"path\[0\] must be a pattern item, 0 to 0"),
    (lambda e: e[0].update(path=[0, 5]), r"path\[1\] is 5, but that node lays out 5 children"),
    (lambda e: e[0].update(path=[0, 3, 1, 1, 0]), r"path\[4\] goes below a leaf"),
    (lambda e: e[0].update(size=["rel", 2]), r"exceptions\[0\].size is a relative size above 1"),
    (lambda e: e[0].update(colour="red"), r"unexpected key\(s\): colour"),
    (lambda e: e.append(dict(e[0])), r"names copy 1 at path \[0, 3, 1, 1\] twice"),
    (lambda e: e[0].update(copy=4, path=[0]), r"copy 4 is the tail, which lays out nothing"),
    (lambda e: e[0]["node"].update(label="tree"), r"node root/1/!0: leaf label 'tree'"),
])
def test_bad_exceptions_are_refused_by_name(change, message):
    with pytest.raises(ProcedureError, match=message):
        Procedure.from_dict(_mutated(change))


def test_exceptions_only_on_repeats():
    obj = example().to_dict()
    obj["root"]["exceptions"] = []
    with pytest.raises(ProcedureError, match="unexpected key"):
        Procedure.from_dict(obj)


def test_the_tail_is_the_copy_after_the_last():
    """``copy == count`` names the tail; an item the tail does not lay out is refused."""
    row = Node.repeat("x", 3, [(Size("abs", 8), leaf("pillar")), (Size("flt", 50), leaf("window"))], tail=1)
    row.exceptions = [Override(3, (0,), node=leaf("deco"))]
    proc = Procedure(200, 50, row)
    validate_round_trip(proc)
    assert [lab for lab, *_ in execute(proc)][-1] == 8  # deco
    row.exceptions = [Override(3, (1,), node=leaf("deco"))]
    with pytest.raises(ProcedureError, match="is the tail, which lays out items 0 to 0"):
        Procedure.from_dict(proc.to_dict())


def validate_round_trip(proc: Procedure) -> None:
    assert Procedure.from_json(proc.to_json()).to_json() == proc.to_json()


def test_a_fill_repeat_ignores_copies_it_does_not_lay_out():
    row = Node.repeat("x", "fill", [(Size("flt", 50), leaf("window"))])
    row.exceptions = [Override(1, (0,), node=leaf("door")), Override(6, (0,), node=leaf("shop"))]
    narrow, wide = Procedure(200, 50, row), Procedure(400, 50, row)
    assert [lab for lab, *_ in execute(narrow)] == [2, 3, 2, 2]
    assert [lab for lab, *_ in execute(wide)] == [2, 3, 2, 2, 2, 2, 11, 2]
    assert count_leaves(row, 400, 50) == 8


def test_an_exception_from_further_up_wins():
    """A column's exception (on the row) and a cell's (on the floors) at the same node: the cell's applies."""
    proc = facade([Override(2, (0, 1), node=leaf("door"))], bays=[Override(1, (0,), node=leaf("shop"))])
    labels = [lab for lab, *_ in execute(proc)]
    assert labels.count(3) == 1 and labels.count(11) == 3  # a door in floor 2, a shop in the other three


def test_parameters_include_the_exceptions_sizes():
    proc = example()
    values = proc.parameters()
    assert len(values) == sum(len(n.sizes) for _, n in proc.nodes()) + 3
    assert proc.with_parameters(values).to_dict() == proc.to_dict()
    moved = proc.with_parameters([v * 1.1 for v in values])
    assert moved.root.children[1].exceptions[1].size == Size("flt", 120 * 1.1)
    paths = [p for p, _ in proc.nodes()]
    assert "root/1/!0" in paths and "root/1/!2" in paths


def test_first_boxes_reach_the_exceptions_nodes():
    proc = example()
    boxes = first_boxes(proc)
    blind = proc.root.children[1].exceptions[0].node
    assert boxes[id(blind)][1] > 100  # the blind's box is on floor 1, not where the typical copy was first seen


def reference_rows(proc: Procedure, wall: str = "pieces") -> np.ndarray:
    return flatten_array_numpy(round(proc.width), round(proc.height), leaf_array(proc, execute(proc)), wall)


@needs_c
@pytest.mark.parametrize("style", [None, "wings", "tenement", "commercial"])
def test_the_c_executes_exceptions_as_python_does(style):
    rng = np.random.default_rng(7)
    changed = 0
    for seed in range(40):
        plain = generate_procedure(seed, style)
        proc = random_exceptions(plain, rng)
        assert np.array_equal(flat_rows(proc), reference_rows(proc))
        got = rects.executed_rows(proc.root, (proc.width, proc.height), 256, 100_000, wall="footprint")
        assert np.array_equal(got, reference_rows(proc, "footprint"))
        changed += not np.array_equal(flat_rows(proc), flat_rows(plain))
    assert changed > 20  # the exceptions do change most of these facades


@needs_c
def test_the_c_executes_the_example():
    proc = example()
    assert np.array_equal(flat_rows(proc), reference_rows(proc))


@pytest.mark.parametrize("seed", range(6))
def test_the_torch_executor_shares_and_separates_parameters(seed):
    """Moved parameters (the exceptions' sizes among them) give the numeric executor's boxes, and gradients
    reach the exceptions' sizes."""
    proc = random_exceptions(generate_procedure(seed), np.random.default_rng(seed), n=10)
    plan = compile_plan(proc)
    rng = np.random.default_rng(seed)
    values = [v if s == "rel" else v * rng.uniform(0.7, 1.3)
              for v, s in zip(proc.parameters(), [s.mode for _, n in proc.nodes() for s in n.own_sizes()],
                              strict=True)]
    want = torch.tensor([leaf[1:] for leaf in execute(proc.with_parameters(values))], dtype=torch.float64)
    params = torch.tensor(values, dtype=torch.float64, requires_grad=True)
    got = execute_plan(plan, params)
    torch.testing.assert_close(got, want, rtol=0, atol=1e-7)
    got.sum().backward()
    assert params.grad is not None


def test_gradcheck_with_exceptions():
    proc = example()
    plan = compile_plan(proc)
    params = plan.values.clone().requires_grad_(True)
    torch.autograd.gradcheck(lambda x: execute_plan(plan, x, with_overflow=True), (params,))
    sizes = len(proc.parameters())
    grad = torch.autograd.functional.jacobian(lambda x: execute_plan(plan, x), plan.values)
    assert grad.shape[-1] == sizes
    taller = sum(len(n.sizes) for _, n in proc.nodes() if n is proc.root or n is proc.root.children[1]) + 1
    assert grad[..., taller].abs().sum() > 0  # floor 3's own height moves boxes


def test_copies_keep_sharing_their_pattern():
    """An exception adds its own leaves only: the typical copies still cost one subtree."""
    proc = example()
    typical = sum(1 for _, n in facade([]).nodes() if n.rule == "leaf")
    assert sum(1 for _, n in proc.nodes() if n.rule == "leaf") == typical + 2


def test_the_model_grammar_has_no_exceptions():
    with pytest.raises(ValueError, match="no exceptions"):
        Tokenizer().encode_procedure(example())
    Tokenizer().encode_procedure(facade([]))


def test_copy_is_deep():
    proc = example()
    twin = proc.root.copy()
    twin.children[1].exceptions[0].node.label = "door"
    assert proc.root.children[1].exceptions[0].node.label == "blind"
    assert copy.deepcopy(proc).to_json() == proc.to_json()


def _counts(proc: Procedure) -> dict[str, int]:
    labels = [lab for lab, x0, y0, x1, y1 in execute(proc) if x1 - x0 > 0.5 and y1 - y0 > 0.5]
    return {name: labels.count(i) for name, i in (("window", 2), ("blind", 7), ("sill", 5))}


def test_named_parameters_edit_the_typical_copies():
    """floors + 1 adds a typical floor after the last typical one, bays + 1 a typical tile to every floor; the
    exceptions stay on their copies (floors - 1 takes a typical floor away), and the lengths change the typical
    copies only."""
    proc = example()
    assert np.array_equal(label_map(normalised(proc)), label_map(proc))
    assert _counts(proc) == {"window": 19, "blind": 1, "sill": 19}
    more = set_parameter(proc, "floors", 5)
    assert _counts(more) == {"window": 24, "blind": 1, "sill": 24}
    assert more.height == pytest.approx(proc.height + 360 * 90 / 390, abs=0.01)  # one typical floor taller
    assert [o.copy for o in more.root.children[1].exceptions] == [1, 4, 0]  # the new floor after floor 2
    fewer = set_parameter(proc, "floors", 3)
    assert [o.copy for o in fewer.root.children[1].exceptions] == [1, 2, 0]  # a typical floor went
    assert _counts(fewer) == {"window": 14, "blind": 1, "sill": 14}
    wider = set_parameter(proc, "bays", 6)
    assert _counts(wider) == {"window": 23, "blind": 1, "sill": 23}
    typical = {p.name: p.value for p in named_parameters(proc)}["floor_height"]
    assert typical == pytest.approx(360 * 90 / 390, abs=0.01)  # the typical floor, not the taller one
    taller = set_parameter(proc, "floor_height", 120)
    assert {p.name: p.value for p in named_parameters(taller)}["floor_height"] == pytest.approx(120)
    assert taller.height == pytest.approx(proc.height + 3 * (120 - typical), abs=0.01)
    own = [o.size.value for o in taller.root.children[1].exceptions if o.size is not None and o.path == (0,)]
    assert own == [pytest.approx(360 * 120 / 390, abs=0.01)]  # the taller floor keeps its own height


def test_a_count_change_keeps_paths_through_the_repeat():
    """A tile exception of floor 1 sits at tile 3 of the row: with one bay fewer it stays; with tile 3 gone it goes."""
    proc = facade([Override(1, (0, 3, 1, 1), node=leaf("blind")), Override(1, (0, 1, 1, 1), node=leaf("door"))])
    row = proc.root.children[1].children[0]
    recount(proc.root, row, 3)
    assert [o.path for o in proc.root.children[1].exceptions] == [(0, 1, 1, 1)]
    validate(proc)


@pytest.mark.parametrize("style", [None, "wings", "tenement"])
def test_every_named_parameter_on_trees_with_exceptions(style):
    """Read and set on random exceptions: a valid procedure or a ValueError naming the problem, never another
    error (an exception whose node is never laid out, a copy removed, a path through a replaced item)."""
    rng = np.random.default_rng(11)
    for seed in range(12):
        proc = random_exceptions(generate_procedure(seed, style), rng, n=12)
        for p in named_parameters(proc):
            for value in (p.value + 1, p.value - 1, p.value * 1.25):
                try:
                    out = set_parameter(proc, p.name, value)
                except ValueError:
                    continue
                validate(out)
                flat_rows(out)


def test_bays_plus_one_keeps_the_rows_of_tiles_in_step():
    """A new tile goes after the last typical tile of the most laid-out row (the floors'), and in every other row of
    as many tiles at the same place, so that the ground floor's door stays under its column."""
    row = Node.repeat("x", 5, [(Size("flt", 60), tile())], role="floor")
    row.exceptions = [Override(3, (0,), node=leaf("deco")), Override(4, (0,), node=leaf("deco"))]
    floors = Node.repeat("y", 3, [(Size("flt", 90), row)], role="floors")
    ground = Node.repeat("x", 5, [(Size("flt", 60), tile(window="shop"))], role="ground")
    ground.exceptions = [Override(3, (0,), node=leaf("door"))]
    proc = Procedure(300, 370, Node.split("y", [(Size("flt", 270), floors), (Size("flt", 100), ground)]))
    wider = set_parameter(proc, "bays", 6)
    rows = [n for _, n in wider.nodes() if n.rule == "repeat" and n.axis == "x"]
    assert [o.copy for o in rows[0].exceptions] == [4, 5]  # the floors' own tiles after the new one (copy 3)
    assert [o.copy for o in rows[1].exceptions] == [4]  # the door moved with its column, not left under the new one


def test_a_new_bay_repeats_a_real_column_on_every_floor():
    """Where a floor differs in every cell (a lattice reading's floor of balconies, written as deltas of the floors'
    repeat), a new bay is a copy of the column fewest floors change, on every floor: that floor's new cell has its
    balcony too, not the typical floor's tile (b0002's and b0006's new columns were the typical tile throughout)."""
    row = Node.repeat("x", 4, [(Size("flt", 60), tile())], role="floor")
    floors = Node.repeat("y", 3, [(Size("flt", 90), row)], role="floors")
    floors.exceptions = [Override(1, (0, j, 1, 2), node=leaf("balcony")) for j in range(4)]
    floors.exceptions.append(Override(2, (0, 2, 1, 1), node=leaf("blind")))
    proc = Procedure(240, 270, floors)
    assert most_typical(proc.root, row) == 3  # column 2 has the blind as well
    wider = set_parameter(proc, "bays", 5)
    validate(wider)
    count = {name: len(region_boxes(flat_rows(wider), (LABEL_ID[name],))) for name in ("balcony", "blind", "window")}
    assert count == {"balcony": 5, "blind": 1, "window": 14}
    narrower = set_parameter(proc, "bays", 3)  # a copy fewer takes that column: the blind stays
    assert len(region_boxes(flat_rows(narrower), (LABEL_ID["blind"],))) == 1


def test_a_repeat_whose_copies_all_have_their_own_size_takes_its_share():
    """floors + 1 pads the neighbour of the floors with the new floor's height; where each copy of the neighbour's
    repeat has its own size, those sizes share it (there was a division by zero: no copy took the typical size)."""
    floors = Node.repeat("y", 4, [(Size("flt", 90), Node.repeat("x", 5, [(Size("flt", 60), tile())], role="floor"))],
                         role="floors")
    side = Node.repeat("y", 3, [(Size("flt", 120), leaf("deco"))])
    side.exceptions = [Override(c, (0,), size=Size("flt", h)) for c, h in enumerate((100, 140, 120))]
    proc = Procedure(360, 360, Node.split("x", [(Size("flt", 300), floors), (Size("abs", 60), side)]))
    more = set_parameter(proc, "floors", 5)
    validate(more)
    assert more.height == 450
    assert [o.size.value for o in more.root.children[1].exceptions] == [130, 170, 150]
    assert np.all(label_map(more)[:, 300:] == LABEL_ID["deco"])


def test_exceptions_count_towards_the_node_limit():
    from facaid.grammar.limits import MAX_NODES

    row = Node.repeat("x", 256, [(Size("flt", 1), leaf("window"))])
    row.exceptions = [Override(c, (0,), size=Size("flt", 2)) for c in range(256)]
    rows = Node.split("y", [(Size("flt", 1), row.copy()) for _ in range(MAX_NODES // 256 + 1)][:64])
    with pytest.raises(ProcedureError, match=f"too many nodes and exceptions \\(more than {MAX_NODES}\\)"):
        Procedure.from_dict(Procedure(4000, 4000, Node.split("x", [(Size("flt", 1), rows.copy())
                                                                    for _ in range(2)])).to_dict())


def test_a_copy_fewer_keeps_a_copy_that_lays_out_the_pattern():
    """Where the only typical copy is the one that lays the pattern's row out (the other puts its own row in place: a
    lattice reading's balcony floor), one floor fewer takes the other away: without the typical one the pattern's
    own exceptions would never be laid out, and the tree would be refused."""
    row = Node.repeat("x", 2, [(Size("flt", 50), Node.leaf("window"))])
    row.exceptions = [Override(1, (0,), node=Node.leaf("blind"))]
    floor = Node.split("x", [(Size("flt", 100), row)])
    floors = Node.repeat("y", 2, [(Size("flt", 50), floor)], role="floors")
    floors.exceptions = [Override(0, (0, 0), node=Node.repeat("x", 2, [(Size("flt", 50), Node.leaf("shop"))]))]
    proc = Procedure(100, 100, floors)
    validate(proc)
    assert copies_moved(floors, 1) == {1: 0, 2: 1}  # the typical copy stays, the one with its own row goes
    recount(proc.root, floors, 1)
    validate(proc)
    assert floors.exceptions == []
