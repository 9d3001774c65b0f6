import copy
import json
from pathlib import Path

import pytest
import torch

import facaid.grammar as grammar_pkg
from facaid.grammar import Node, Procedure, ProcedureError, Size, execute, layout, to_segmentation, validate
from facaid.grammar.differentiable import compile_plan, execute_plan, execute_torch
from facaid.grammar.procedure import MAX_DEPTH, MAX_NODES
from facaid.labels import LABELS

A, F, R = (lambda v: Size("abs", v)), (lambda v: Size("flt", v)), (lambda v: Size("rel", v))
L = Node.leaf


def sample_procedure() -> Procedure:
    column = Node.split("y", [(F(1), L("facade")), (A(30), L("cornice")), (A(40), L("window")), (A(5), L("sill")),
                              (F(2), L("facade"))])
    tile = Node.split("x", [(F(1), L("facade")), (A(30), column), (F(1), L("facade"))], role="tile")
    floor = Node.repeat("x", 5, [(A(10), L("pillar")), (F(60), tile)], tail=1, role="floor")
    ground = Node.mirror("x", [(A(50), L("shop")), (F(1), L("facade")), (A(40), L("door"))], center=True)
    root = Node.split("y", [(R(0.1), L("background")), (F(1), Node.repeat("y", 3, [(F(80), floor)])),
                            (A(100), ground)], role="image")
    return Procedure(400, 500, root)


def test_layout_rules():
    assert layout([A(10), F(1), F(3)], 50) == [10, 10, 30]
    assert layout([R(0.5), F(1)], 50) == [25, 25]
    assert layout([A(40), A(60), F(1)], 50) == [20, 30, 0]  # overflow: fixed scaled down, floats get nothing
    assert layout([A(10), A(30)], 80) == [20, 60]  # no float: fixed scaled to fill
    assert layout([A(0), A(0)], 80) == [0, 0]
    # a region rounding left a hair below zero long: nothing to share, and no division by zero
    assert layout([F(0.17)], -1.1e-13) == [0] and layout([A(5), F(1)], -1e-13) == [0, 0]


def test_execution_partitions_the_image():
    p = sample_procedure()
    leaves = execute(p)
    area = sum((x1 - x0) * (y1 - y0) for _, x0, y0, x1, y1 in leaves)
    assert area == pytest.approx(400 * 500)
    seg = to_segmentation(p)
    cover = torch.zeros(500, 400, dtype=torch.int32)
    for r in seg.rects:
        cover[r.y0:r.y1, r.x0:r.x1] += 1
    assert cover.max() == 1  # nothing overlaps
    assert int((cover == 0).sum()) == 400 * 50  # only the background band is uncovered


def test_repeat_with_tail_and_mirror_reflection():
    p = sample_procedure()
    labels = [LABELS[lab] for lab, *_ in execute(p)]
    assert labels[0] == "background"
    # three floors of pillar tile pillar tile ... pillar: six pillars each
    assert labels.count("pillar") == 3 * 6
    # the mirror: shop, wall, door, wall, shop, left to right
    ground = [(LABELS[lab], x0) for lab, x0, y0, *_ in execute(p) if y0 >= 400]
    assert [name for name, _ in ground] == ["shop", "facade", "door", "facade", "shop"]
    xs = [x for _, x in ground]
    assert xs == sorted(xs)


def test_mirror_reflects_asymmetric_children():
    inner = Node.split("x", [(A(10), L("door")), (F(1), L("window"))])
    root = Node.mirror("x", [(F(1), inner)])
    boxes = [(LABELS[lab], x0, x1) for lab, x0, _, x1, _ in execute(Procedure(100, 10, root))]
    assert boxes == [("door", 0, 10), ("window", 10, 50), ("door", 90, 100), ("window", 50, 90)]


def test_fill_repeat_counts_from_nominal_sizes():
    root = Node.repeat("x", "fill", [(A(5), L("pillar")), (F(40), L("window"))], tail=1)
    labels = [LABELS[lab] for lab, *_ in execute(Procedure(455, 10, root))]
    assert labels.count("window") == 10 and labels.count("pillar") == 11


def test_json_round_trip_is_exact():
    p = sample_procedure()
    p.meta = {"style": "test", "seed": 3}
    text = p.to_json()
    q = Procedure.from_json(text)
    assert q.to_json() == text
    assert q.to_dict() == json.loads(text)
    assert Procedure.from_json(p.to_json(indent=2)).to_json() == text


def test_schema_file_matches_the_parser():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((Path(grammar_pkg.__file__).parent / "procedure.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    obj = sample_procedure().to_dict()
    jsonschema.validate(obj, schema)
    bad = copy.deepcopy(obj)
    bad["root"]["sizes"][0] = ["abs", -1]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)


def _broken(mutate):
    obj = sample_procedure().to_dict()
    mutate(obj)
    return obj


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda o: o["root"].update(rule="spiral"), "node root: unknown rule 'spiral'"),
        (lambda o: o["root"]["children"][1].update(sizes=[]), "node root/1: wrong arity: 0 sizes for 1 children"),
        (lambda o: o["root"]["sizes"].__setitem__(2, ["abs", -4]), "node root: sizes[2] is negative"),
        (lambda o: o["root"]["sizes"].__setitem__(2, ["abs", float("nan")]), "must be finite"),
        (lambda o: o["root"]["sizes"].__setitem__(2, ["abs", "3"]), "must be a number"),
        (lambda o: o["root"]["sizes"].__setitem__(2, ["abs", 1e9]), "too large"),
        (lambda o: o["root"]["sizes"].__setitem__(0, ["rel", 1.5]), "relative size above 1"),
        (lambda o: o["root"]["sizes"].__setitem__(0, ["px", 1]), "unknown mode 'px'"),
        (lambda o: o["root"]["sizes"].__setitem__(0, 5), "must be a [mode, value] pair"),
        (lambda o: o["root"]["children"][0].update(label="roof"), "node root/0: leaf label 'roof'"),
        (lambda o: o["root"].update(axis="z"), "axis must be 'x' or 'y'"),
        (lambda o: o["root"]["children"][1].update(count=0), "node root/1: count must be between 1"),
        (lambda o: o["root"]["children"][1].update(count="many"), "count must be a positive integer or 'fill'"),
        (lambda o: o["root"]["children"][1]["children"][0].update(tail=2), "node root/1/0: tail must be"),
        (lambda o: o["root"]["children"][2].update(center="yes"), "node root/2: center must be true or false"),
        (lambda o: o["root"].update(colour="red"), "unexpected key(s) for a split node: colour"),
        (lambda o: o["root"].update(role="spaceship"), "unknown role 'spaceship'"),
        (lambda o: o.update(width=float("inf")), "width must be a number"),
        (lambda o: o.update(height=-5), "height must be a number"),
        (lambda o: o.update(grammar="facaid-split-0"), "made for grammar 'facaid-split-0'"),
        (lambda o: o.update(version=2), "unsupported version 2"),
        (lambda o: o.pop("root"), "missing 'root'"),
    ],
)
def test_invalid_procedures_name_the_node(mutate, message):
    with pytest.raises(ProcedureError) as err:
        Procedure.from_dict(_broken(mutate))
    assert message in str(err.value)


def test_malformed_json():
    with pytest.raises(ProcedureError, match="malformed JSON"):
        Procedure.from_json("{")
    with pytest.raises(ProcedureError, match="must be a JSON object"):
        Procedure.from_json("[1, 2]")


def test_too_deep_and_too_many_nodes():
    node = {"rule": "leaf", "label": "window"}
    for _ in range(MAX_DEPTH + 1):
        node = {"rule": "split", "axis": "x", "sizes": [["flt", 1]], "children": [node]}
    doc = {"format": "facaid-procedure", "version": 1, "grammar": "facaid-split-1", "width": 10, "height": 10,
           "root": node}
    with pytest.raises(ProcedureError, match="tree too deep"):
        Procedure.from_dict(doc)
    door = {"rule": "leaf", "label": "door"}
    pair = {"rule": "split", "axis": "x", "sizes": [["flt", 1]] * 2, "children": [door] * 2}
    wide = {"rule": "split", "axis": "x", "sizes": [["flt", 1]] * 64,
            "children": [{"rule": "split", "axis": "y", "sizes": [["flt", 1]] * 64, "children": [pair] * 64}] * 64}
    doc["root"] = wide
    with pytest.raises(ProcedureError, match=f"too many nodes \\(more than {MAX_NODES}\\)"):
        Procedure.from_dict(doc)


def test_expansion_limit():
    leaf = {"rule": "leaf", "label": "window"}
    rep = {"rule": "repeat", "axis": "x", "count": 256, "tail": 0, "sizes": [["flt", 1]], "children": [leaf]}
    rep2 = {"rule": "repeat", "axis": "y", "count": 256, "tail": 0, "sizes": [["flt", 1]], "children": [rep]}
    doc = {"format": "facaid-procedure", "version": 1, "grammar": "facaid-split-1", "width": 1000, "height": 1000,
           "root": {"rule": "repeat", "axis": "x", "count": 2, "tail": 0, "sizes": [["flt", 1]], "children": [rep2]}}
    with pytest.raises(ProcedureError, match="more than 100000 node instances"):
        Procedure.from_dict(doc)


def test_numeric_and_torch_paths_agree():
    p = sample_procedure()
    labels, boxes = execute_torch(p)
    ref = execute(p)
    assert labels.tolist() == [lab for lab, *_ in ref]
    assert torch.allclose(boxes, torch.tensor([x[1:] for x in ref], dtype=torch.float64), atol=1e-9)


def test_torch_path_follows_changed_parameters():
    p = sample_procedure()
    plan = compile_plan(p)
    values = [v * 1.3 + 0.5 for v in p.parameters()]
    values[0] = 0.2  # the background band's relative size stays within [0, 1]
    q = p.with_parameters(values)
    got = execute_plan(plan, torch.tensor(values, dtype=torch.float64))
    ref = torch.tensor([x[1:] for x in execute(q)], dtype=torch.float64)
    assert torch.allclose(got, ref, atol=1e-9)


def test_gradients_reach_every_parameter():
    p = sample_procedure()
    plan = compile_plan(p)
    params = plan.values.clone().requires_grad_(True)
    boxes = execute_plan(plan, params)
    weights = torch.linspace(0.1, 1.0, boxes.numel(), dtype=torch.float64).reshape(boxes.shape)
    (boxes * weights).sum().backward()
    assert torch.isfinite(params.grad).all()
    # every fixed size moves some edge, so its gradient under generic weights is non-zero; a floating size
    # matters only next to another floating sibling
    modes = [s.mode for _, node in p.nodes() for s in node.sizes]
    for mode, grad in zip(modes, params.grad.tolist(), strict=True):
        if mode != "flt":
            assert abs(grad) > 1e-6
    assert abs(params.grad[6]) > 1e-6  # the wall on the left of a tile: a floating size beside another
    torch.autograd.gradcheck(lambda x: execute_plan(plan, x), (plan.values.clone().requires_grad_(True),))


def test_with_parameters_validates():
    p = sample_procedure()
    values = p.parameters()
    values[3] = -1.0
    with pytest.raises(ProcedureError, match="negative"):
        p.with_parameters(values)
    with pytest.raises(ValueError, match="expected"):
        p.with_parameters(values[:-1])


def test_leaf_count_is_the_executed_count_and_stops_past_the_limit():
    from facaid.generator import generate_procedure
    from facaid.grammar.execute import execute_with_boxes, first_boxes
    from facaid.grammar.layout import count_leaves
    from facaid.grammar.limits import MAX_LEAVES

    for seed in range(60):
        proc = generate_procedure(seed)
        leaves, boxes = execute_with_boxes(proc)
        assert count_leaves(proc.root, proc.width, proc.height) == len(leaves)
        assert first_boxes(proc) == boxes  # visiting each node once finds the same first boxes
    cell = Node.leaf("window")
    row = Node.repeat("x", 256, [(Size("flt", 1.0), cell)])
    grid = Node.repeat("y", 256, [(Size("flt", 1.0), row)])
    huge = Procedure(1000, 1000, Node.repeat("x", 2, [(Size("flt", 1.0), grid)]))  # 131,072 leaves
    assert count_leaves(huge.root, 1000, 1000) == MAX_LEAVES + 1
    assert count_leaves(grid, 1000, 1000, limit=10**6) == 65_536
    with pytest.raises(ProcedureError, match="expands to more than 100000 node instances"):
        validate(huge)


def _instances(node, w: float, h: float, pending=None) -> int:
    """Node instances laid out, counted the slow way: every copy visited."""
    from facaid.grammar.layout import expand_over, layout

    if node.rule == "leaf":
        return 1
    length = w if node.axis == "x" else h
    sizes, children, _, below, _ = expand_over(node, length, pending)
    return 1 + sum(_instances(c, e, h, below[i] if below else None) if node.axis == "x"
                   else _instances(c, w, e, below[i] if below else None)
                   for i, (c, e) in enumerate(zip(children, layout(sizes, length), strict=True)))


def test_the_cost_model_counts_every_instance_and_refuses_a_crafted_tree_before_any_work():
    """Issue 56's tree: 2 KB, 65,536 leaves (under the rectangle limit), each under 29 one-child splits: 2 million
    node instances to lay out. Counted from its 32 distinct nodes, refused by name; what generated facades cost is
    counted exactly, and the largest of them is far under the limit."""
    from facaid.generator import generate_procedure
    from facaid.grammar.layout import count_expansion
    from facaid.grammar.limits import MAX_INSTANCES

    leaf = Node.leaf("window")
    for _ in range(29):
        leaf = Node.split("y", [(Size("flt", 1.0), leaf)])
    crafted = Procedure(4096, 4096, Node.repeat("x", 256, [(Size("flt", 1.0), Node.repeat(
        "y", 256, [(Size("flt", 1.0), leaf)]))]))
    assert len(json.dumps(crafted.to_dict())) < 2500
    assert count_expansion(crafted.root, 4096, 4096, max_instances=10**8) == (65_536, 1 + 256 + 65_536 * 30)
    assert count_expansion(crafted.root, 4096, 4096).instances == MAX_INSTANCES + 1  # stops at the limit
    with pytest.raises(ProcedureError, match="more than 100000 node instances"):
        Procedure.from_dict(crafted.to_dict())
    most = 0
    for seed in range(40):
        proc = generate_procedure(seed)
        cost = count_expansion(proc.root, proc.width, proc.height)
        assert cost.instances == _instances(proc.root, proc.width, proc.height)
        most = max(most, cost.instances)
    assert most * 20 < MAX_INSTANCES


def test_a_work_budget_bounds_the_trees_one_request_makes():
    from facaid.editing.parameters import set_parameters
    from facaid.generator import generate_procedure
    from facaid.grammar.budget import WorkLimitError, spent, work_budget
    from facaid.grammar.layout import count_expansion

    proc = generate_procedure(3)
    cost = count_expansion(proc.root, proc.width, proc.height).instances
    assert spent() is None
    validate(proc)  # outside a budget nothing is counted
    with work_budget(3 * cost):
        validate(proc)
        assert spent() == cost
        validate(proc)
        validate(proc)
        with pytest.raises(WorkLimitError, match=f"more than {3 * cost:,} node instances in all"):
            validate(proc)
    with work_budget(cost + 1), pytest.raises(WorkLimitError):
        set_parameters(Procedure.from_dict(proc.to_dict()), {"width": proc.width + 10, "height": proc.height + 10})
    with work_budget(10**9, seconds=0.0), pytest.raises(WorkLimitError, match="more than 0 s of computing"):
        sum(range(10**5))  # some CPU time
        validate(proc)
    assert spent() is None


def test_a_work_budget_says_how_much_cpu_time_it_has_left():
    from facaid.grammar.budget import seconds_left, work_budget

    assert seconds_left() is None
    with work_budget(10):
        assert seconds_left() == float("inf")
    with work_budget(10, seconds=5.0):
        first = seconds_left()
        sum(range(10**6))
        assert 0 < seconds_left() < first <= 5.0
    with work_budget(10, seconds=0.0):
        sum(range(10**5))
        assert seconds_left() == 0.0
