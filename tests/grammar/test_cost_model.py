"""The cost model counts what runs (issue 66): an exception is charged at every level its path is carried through,
a path that names nothing laid out is refused, and the CPU time of any tree accepted is within a small factor of
what it is charged, over trees drawn with exceptions, fills, mirrors and chains of one-child splits."""

import json
from time import thread_time

import numpy as np
import pytest
from grammar_helpers import doc, example, nested, probe, random_exceptions
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from facaid.editing.parameters import named_parameters
from facaid.formats.cga import procedure_cga
from facaid.generator import generate_procedure
from facaid.grammar.checks import least_units, least_units_of_json
from facaid.grammar.execute import Trace, execute, first_boxes, flat_rows
from facaid.grammar.layout import count_expansion, expand_over, layout
from facaid.grammar.limits import MAX_INSTANCES
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import Procedure, ProcedureError
from facaid.grammar.repeats import expanded_count, pattern_child


def units(node, w: float, h: float, pending: list | None = None) -> int:
    """The units of work a walk handles, counted the slow way, every instance visited (`expand_over` per
    exception): each node instance, each exception of its own and each one carried through it."""
    carried = len(pending) if pending else 0
    if node.rule == "leaf":
        return 1 + carried
    length = w if node.axis == "x" else h
    sizes, children, _, below, _ = expand_over(node, length, pending)
    total = 1 + carried + len(node.exceptions)
    for i, (child, extent) in enumerate(zip(children, layout(sizes, length), strict=True)):
        sub = below[i] if below else None
        total += units(child, extent, h, sub) if node.axis == "x" else units(child, w, extent, sub)
    return total


def test_the_probes_tree_is_refused_for_what_its_exceptions_cost():
    """1,024 exceptions carried down 29 levels in each of 2,816 copies of R: 84 million units, where the old count
    saw 95,756 instances (and a render took 206 s). Refused by its count, before any of it is laid out."""
    for tree in (probe(), probe(count=256), probe(rows=100, columns=1, count=256)):
        with pytest.raises(ProcedureError, match="more than 100000 node instances"):
            Procedure.from_dict(tree)
    one = Procedure.from_dict(probe(rows=1, columns=1, count=256))  # one copy of R is accepted: 31,826 units
    cost = count_expansion(one.root, one.width, one.height).instances
    assert cost == units(one.root, one.width, one.height) == 1 + 1 + (1 + 1024) + 28 * 1025 + (1 + 1024) + 1024
    three = Procedure.from_dict(probe(rows=3, columns=1, count=256))  # each copy of R its own 31,824
    assert count_expansion(three.root, 4096, 4096).instances == 1 + 3 * (cost - 1)
    assert bound(three.root) == 1 + 3 * (1 + (1 + 1024) + 28 + (1 + 1024 * 1))  # each copy: R, its chain, 4 leaves
    many = probe(rows=4, columns=1, count=256)
    with pytest.raises(ProcedureError, match="more than 100000 node instances"):
        Procedure.from_dict(many)


def test_a_path_that_names_nothing_laid_out_is_refused():
    """The probe's paths into a ``"fill"`` repeat that lays out one copy of 4 leaves name children 4 to 1,023 that
    are never laid out: refused, by the first such exception. A path below a leaf says so."""
    with pytest.raises(ProcedureError, match=r"exceptions\[4\]\.names copy 0 at path \[0, 0, .* 4\], which is never "
                                             "laid out at this size"):
        Procedure.from_dict(probe(rows=1, columns=1))
    assert Procedure.from_dict(probe(rows=1, columns=1, exceptions=4))  # those laid out are fine
    row = Node.repeat("x", "fill", [(Size("flt", 50), Node.leaf("window"))])
    row.exceptions = [Override(1, (0,), node=Node.leaf("door")), Override(6, (0,), node=Node.leaf("shop"))]
    assert Procedure.from_dict(Procedure(400, 50, row).to_dict())  # 8 copies: copy 6 is laid out
    with pytest.raises(ProcedureError, match=r"root: exceptions\[1\]\.names copy 6"):
        Procedure.from_dict(Procedure(200, 50, row).to_dict())  # 4 copies
    proc = example()
    proc.root.children[1].exceptions.append(Override(2, (0, 1, 1, 1, 0), node=Node.leaf("door")))
    with pytest.raises(ProcedureError, match=r"exceptions\[3\]\.path\[4\] goes below a leaf"):
        Procedure.from_dict(proc.to_dict())


def test_the_count_is_the_units_every_walk_handles():
    """Counted from the distinct nodes and the paths' trie, the units are those of visiting every instance and
    handling every exception there, on generated facades with random exceptions and the docs' example."""
    rng = np.random.default_rng(66)
    trees = [example()] + [random_exceptions(generate_procedure(seed, style), rng, n=12)
                           for seed in range(12) for style in (None, "tenement")]
    assert sum(bool(n.exceptions) for t in trees for _, n in t.nodes()) > 20
    for proc in trees:
        assert count_expansion(proc.root, proc.width, proc.height).instances == units(proc.root, proc.width,
                                                                                      proc.height)


def test_a_tree_sent_sure_to_cost_too_much_is_refused_before_it_is_read():
    """What a person sends is bounded from its JSON first (`least_units_of_json`): the probe is refused by its cost
    even with a malformed exception deep inside, which reading it would have named; code's own trees are read."""
    tree = probe(count=256)
    tree["root"]["children"][0]["children"][0]["exceptions"][5]["size"] = ["abs", -1]
    with pytest.raises(ProcedureError, match="more than 100000 node instances"):
        Procedure.from_json(json.dumps(tree))
    with pytest.raises(ProcedureError, match=r"exceptions\[5\]\.size is negative"):
        Procedure.from_dict(tree)  # not sent: read node by node, and the first problem named
    assert least_units_of_json({"rule": "repeat", "count": "many"}) is None  # not plainly a node: left to the reading


def test_a_costly_subtree_that_is_never_laid_out_is_no_cost():
    """The bound is the root's: a subtree of 16 million units that an exception replaces in the only copy there is
    is never laid out (review of issue 66: it was refused as it was read). A copy that is not one leaves the JSON's
    bound to the reading, which names it."""
    leaf = {"rule": "leaf", "label": "window"}

    def rep(child, n, exceptions=()):
        node = {"rule": "repeat", "axis": "x", "count": n, "sizes": [["flt", 1]], "children": [child]}
        return {**node, "exceptions": list(exceptions)} if exceptions else node

    tree = doc(rep(rep(rep(rep(leaf, 256), 256), 256), 1, [{"copy": 0, "path": [0], "node": leaf}]))
    proc = Procedure.from_json(json.dumps(tree))
    assert count_expansion(proc.root, proc.width, proc.height).instances == 3
    tree["root"]["exceptions"][0]["copy"] = [0]
    assert least_units_of_json(tree["root"]) is None
    with pytest.raises(ProcedureError, match=r"exceptions\[0\]\.copy must be a copy"):
        Procedure.from_json(json.dumps(tree))


def test_parsing_walks_no_path_of_a_tree_refused_for_its_cost():
    """Issue 66's 460 KB tree of 8 nested repeats, each with 1,010 exceptions: its paths were walked one by one, each
    through every exception of the repeats below (1 s). Counted along its trie instead, and refused by its count."""
    text = json.dumps(nested())
    assert len(text) > 150_000
    with pytest.raises(ProcedureError, match="more than 100000 node instances"):
        Procedure.from_json(text)


# --- the invariant, over drawn trees ------------------------------------------------------------------------------

LABELS = ("window", "facade", "door", "balcony", "sill", "blind", "deco")


@st.composite
def subtree(draw, depth: int = 0) -> Node:
    rule = draw(st.sampled_from(("leaf", "split", "repeat", "mirror", "chain"))) if depth < 5 else "leaf"
    if rule == "leaf":
        return Node.leaf(draw(st.sampled_from(LABELS)))
    if rule == "chain":  # one-child splits: what carrying exceptions costs most
        node = draw(subtree(depth + 1))
        for _ in range(draw(st.integers(1, 24))):
            node = Node.split(draw(st.sampled_from("xy")), [(Size("flt", 1.0), node)])
        return node
    axis = draw(st.sampled_from("xy"))
    n = draw(st.integers(1, 4))
    items = [(Size(draw(st.sampled_from(("abs", "flt", "rel"))), draw(st.floats(0.05, 1.0)) * 60),
              draw(subtree(depth + 1))) for _ in range(n)]
    items = [(Size(s.mode, s.value / 60) if s.mode == "rel" else s, c) for s, c in items]
    if rule == "split":
        return Node.split(axis, items)
    if rule == "mirror":
        return Node.mirror(axis, items, center=draw(st.booleans()) and n > 1)
    fill = draw(st.booleans()) and any(s.mode != "rel" and s.value > 0 for s, _ in items)
    return Node.repeat(axis, "fill" if fill else draw(st.integers(1, 64)), items, tail=draw(st.integers(0, n - 1)))


@st.composite
def probes(draw) -> Procedure:
    """The probe's shape, at every size: R, one copy whose exceptions run down a chain of one-child splits to a
    repeat of leaves, in rows x columns copies."""
    bottom = Node.repeat("x", draw(st.sampled_from(("fill", 1, 4, 64, 256))),
                         [(Size("abs", draw(st.floats(1, 5000))), Node.leaf("window"))] * 4)
    node, chain = bottom, draw(st.sampled_from((0, 3, 12, 28)))
    for _ in range(chain):
        node = Node.split("y", [(Size("flt", 1.0), node)])
    r = Node.repeat("y", 1, [(Size("flt", 1.0), node)])
    last = draw(st.sampled_from((1, 4, 64, 1024)))
    r.exceptions = [Override(0, (0, *[0] * chain, x), size=Size("abs", 3.0)) for x in range(last)]
    columns = Node.repeat("x", draw(st.sampled_from((1, 2, 11))), [(Size("flt", 1.0), r)])
    return Procedure(4096, 4096, Node.repeat("y", draw(st.sampled_from((1, 3, 8, 256))), [(Size("flt", 1.0), columns)]))


@st.composite
def drawn(draw) -> Procedure:
    """A tree of every rule, wrapped in up to two repeats of up to 256 copies, with up to 48 exceptions on each of
    up to four repeats, their paths walked down the tree to a random depth (some past what is laid out)."""
    root = draw(subtree())
    for _ in range(draw(st.integers(0, 2))):
        root = Node.repeat(draw(st.sampled_from("xy")), draw(st.integers(1, 256)), [(Size("flt", 1.0), root)])
    proc = Procedure(draw(st.integers(50, 4096)), draw(st.integers(50, 4096)), root)
    repeats = [node for _, node in proc.nodes() if node.rule == "repeat"]
    for node in draw(st.lists(st.sampled_from(repeats), max_size=4)) if repeats else ():
        seen = {(o.copy, o.path) for o in node.exceptions}
        for _ in range(draw(st.integers(1, 48))):
            path = [draw(st.integers(0, len(node.children) - 1))]
            target = node.children[path[0]]
            while target.rule != "leaf" and draw(st.integers(0, 9)) < 8:
                wide = draw(st.integers(0, 9)) == 0  # mostly among the first few children, laid out at any length
                path.append(draw(st.integers(0, min(expanded_count(target), 300 if wide else 4) - 1)))
                target = pattern_child(target, path[-1])
            copy = draw(st.integers(0, 1 if node.count == "fill" else node.count - 1))
            size = Size("abs", draw(st.floats(0, 80))) if draw(st.booleans()) else None
            new = Node.leaf(draw(st.sampled_from(LABELS))) if size is None or draw(st.booleans()) else None
            if (copy, tuple(path)) not in seen:
                seen.add((copy, tuple(path)))
                node.exceptions.append(Override(copy, tuple(path), size, new))
    return proc


def walks(proc: Procedure) -> None:
    """What the site does with a tree it accepts: lay it out (the reference executor, with its trace for the
    torch one, the first boxes, the C), read its named parameters and write its CGA."""
    execute(proc)
    execute(proc, Trace())
    first_boxes(proc)
    flat_rows(proc)
    named_parameters(proc)
    procedure_cga(proc, 0.02)


def bound(root: Node) -> int:
    """`least_units` of ``root``, computed bottom-up as parsing does."""
    bounds: dict[int, int] = {}

    def visit(node: Node) -> int:
        for child in node.children:
            visit(child)
        bounds[id(node)] = least_units(node, bounds)
        return bounds[id(node)]

    return visit(root)


SECONDS_PER_UNIT = 20e-6  # 8x what the walks take together on this project's machine (bench/bench_request_cost.py)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(st.one_of(drawn(), probes()))
def test_an_accepted_trees_cpu_time_is_within_a_factor_of_its_cost(proc):
    start = thread_time()
    try:
        accepted = Procedure.from_dict(proc.to_dict())
    except ProcedureError as exc:
        assert thread_time() - start < 0.5, f"refused after {thread_time() - start:.2f} s: {exc}"
        return
    cost = count_expansion(accepted.root, accepted.width, accepted.height).instances
    assert cost <= MAX_INSTANCES
    assert cost == units(accepted.root, accepted.width, accepted.height)  # what is charged is what is handled
    assert bound(accepted.root) <= cost  # what parsing refuses early is sure to cost too much
    assert least_units_of_json(accepted.to_dict()["root"]) == bound(accepted.root)  # and before it is read, the same
    start = thread_time()
    walks(accepted)
    spent = thread_time() - start
    assert spent <= 0.05 + SECONDS_PER_UNIT * cost, f"{spent:.2f} s for {cost} units"
