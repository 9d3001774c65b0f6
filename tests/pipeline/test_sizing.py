import numpy as np
import pytest
import torch

from facaid.generator import generate
from facaid.grammar import Node, Procedure, Size, to_segmentation
from facaid.grammar.differentiable import compile_plan, execute_plan
from facaid.labels import LABELS
from facaid.metrics import procedure_accuracy, scaled_label_map
from facaid.segmentation import Segmentation
from facaid.sizing import box_integrals, fit_sizes, smoothed_integrals
from facaid.tokenizer import Tokenizer, TokenizerConfig

TOK = Tokenizer(TokenizerConfig(max_rects=2000, max_out=2000))


def quantized(seed):
    s = generate(seed)
    q = TOK.decode_procedure(TOK.encode_procedure(s.procedure)[0], s.procedure.width, s.procedure.height)
    return s, q


@pytest.mark.parametrize("seed", [1, 8, 10])
def test_sizing_recovers_quantized_sizes(seed):
    s, q = quantized(seed)
    result = fit_sizes(q, s.segmentation)
    assert result.accuracy_before < 0.99
    assert result.accuracy >= 0.99
    assert result.accuracy == pytest.approx(procedure_accuracy(result.procedure, s.segmentation))
    assert result.iou["window"] > 0.97


def test_sizing_never_makes_things_worse():
    s, _ = quantized(0)
    other = generate(5).procedure  # a wrong structure
    wrong = Procedure(s.procedure.width, s.procedure.height, other.root)
    result = fit_sizes(wrong, s.segmentation, geometry_rounds=1, polish_steps=5)
    assert result.accuracy >= result.accuracy_before
    # a caller that measured the accuracy before sizing passes it in: the same fit
    again = fit_sizes(wrong, s.segmentation, geometry_rounds=1, polish_steps=5,
                      before=procedure_accuracy(wrong, s.segmentation))
    assert (again.accuracy_before, again.accuracy) == (result.accuracy_before, result.accuracy)
    assert again.procedure.to_dict() == result.procedure.to_dict()


def test_overflow_is_measured_and_pulled_back():
    root = Node.split("x", [(Size("flt", 1), Node.leaf("facade")), (Size("abs", 150), Node.leaf("window")),
                            (Size("flt", 1), Node.leaf("facade"))])
    proc = Procedure(100, 20, root)
    _, overflow = execute_plan(compile_plan(proc), with_overflow=True)
    assert float(overflow) == pytest.approx(50.0)
    target = Segmentation.from_dict({"width": 100, "height": 20, "rects": [
        {"label": "facade", "x0": 0, "y0": 0, "x1": 100, "y1": 20},
        {"label": "window", "x0": 30, "y0": 0, "x1": 70, "y1": 20}]})
    result = fit_sizes(proc, target)
    assert result.accuracy_before == pytest.approx(0.4)  # the window was stretched over everything
    assert result.accuracy > 0.97


def test_size_mismatch_is_an_error():
    s, q = quantized(1)
    small = Segmentation(10, 10, ())
    with pytest.raises(ValueError, match="but the target is 10x10"):
        fit_sizes(q, small)


def _sigmoid_coverage(boxes, labels, w, h, tau):
    """Reference soft rasterizer: per-class coverage (C, H, W), every leaf an outer product of sigmoid edges."""
    u, v = torch.arange(w, dtype=boxes.dtype) + 0.5, torch.arange(h, dtype=boxes.dtype) + 0.5
    mx = torch.sigmoid((u - boxes[:, :1]) / tau) * torch.sigmoid((boxes[:, 2:3] - u) / tau)
    my = torch.sigmoid((v - boxes[:, 1:2]) / tau) * torch.sigmoid((boxes[:, 3:4] - v) / tau)
    onehot = torch.nn.functional.one_hot(labels, len(LABELS)).to(boxes.dtype)
    return torch.einsum("lc,lh,lw->chw", onehot, my, mx)


def _tables_for(seg, scale, labels, tau):
    label_map = scaled_label_map(seg, scale)
    classes = sorted(set(labels.tolist()))
    index = torch.zeros(len(LABELS), dtype=torch.long)
    index[classes] = torch.arange(len(classes))
    return label_map, smoothed_integrals(label_map, classes, tau), index[labels]


def _grid_facade() -> Procedure:
    """198 x 120: a band, then two floors of three windows (30 x 40 px) between walls, integer sizes."""
    tile = Node.split("x", [(Size("abs", 18), Node.leaf("facade")), (Size("abs", 30), Node.leaf("window")),
                            (Size("abs", 18), Node.leaf("facade"))])
    floor = Node.split("y", [(Size("abs", 10), Node.leaf("facade")), (Size("abs", 40), Node.repeat(
        "x", 3, [(Size("abs", 66), tile)])), (Size("flt", 1), Node.leaf("facade"))])
    root = Node.split("y", [(Size("abs", 14), Node.leaf("cornice")), (Size("flt", 1), floor), (Size("flt", 1), floor)])
    return Procedure(198, 120, root)


def test_box_integrals_count_the_pixels_of_each_class_exactly():
    proc = _grid_facade()
    plan = compile_plan(proc)
    label_map, tables, index = _tables_for(to_segmentation(proc), 1.0, plan.labels, 0.0)
    overlap = box_integrals(tables, index, execute_plan(plan))
    assert float(overlap.sum()) == pytest.approx(label_map.size, rel=1e-9)  # every pixel is its leaf's class
    # a box over whole pixels counts the class's pixels in it; a half-pixel edge counts half a column
    boxes = torch.tensor([[10.0, 20.0, 30.0, 60.0], [10.0, 20.0, 30.5, 60.0], [10.0, 20.0, 30.0, 60.25]],
                         dtype=torch.float64)
    window = LABELS.index("window")
    got = box_integrals(tables, torch.full((3,), int(index[plan.labels == window][0])), boxes)
    inside = (label_map[20:60, 10:30] == window).sum()
    column, row = (label_map[20:60, 30] == window).sum(), (label_map[60, 10:30] == window).sum()
    assert min(inside, column, row) > 0
    assert float(got[0]) == pytest.approx(inside)
    assert float(got[1]) == pytest.approx(inside + column / 2)
    assert float(got[2]) == pytest.approx(inside + row / 4)


def test_smoothed_integrals_give_the_sigmoid_rasterizers_overlap_and_gradient():
    proc = _grid_facade()
    plan = compile_plan(proc)
    label_map, tables, index = _tables_for(to_segmentation(proc), 1.0, plan.labels, 1.0)
    h, w = label_map.shape
    target = torch.nn.functional.one_hot(torch.from_numpy(label_map.astype("int64")), len(LABELS))
    target = target.permute(2, 0, 1).double()
    jitter = torch.randn(len(plan.labels), 4, generator=torch.Generator().manual_seed(0), dtype=torch.float64)
    boxes = execute_plan(plan) + 2.0 * jitter  # near, not on, the target's edges
    a = boxes.clone().requires_grad_(True)
    b = boxes.clone().requires_grad_(True)
    closed = box_integrals(tables, index, a).sum()
    reference = (_sigmoid_coverage(b, plan.labels, w, h, 1.0) * target).sum()
    assert closed.item() == pytest.approx(reference.item(), rel=0.01)
    closed.backward()
    reference.backward()
    cos = torch.nn.functional.cosine_similarity(a.grad.flatten(), b.grad.flatten(), dim=0)
    assert cos.item() > 0.95


def test_smoothed_integrals_equal_an_explicit_convolution():
    """Pinned to a plain reference: each class's indicator, edge-padded and convolved with the logistic density
    (13 taps at tau = 1) along both axes, then summed into a table."""
    rng = np.random.default_rng(3)
    label_map = rng.choice(np.array([0, 1, 2, 5], dtype=np.uint8), size=(37, 53), p=[0.1, 0.5, 0.3, 0.1])
    label_map[10:20, 5:40] = 2  # a block, so the smoothing has edges to blur as well as noise
    for tau in (1.0, 0.5, 0.0):
        got = smoothed_integrals(label_map, [1, 2, 5], tau).numpy()
        assert got.shape == (3, 38, 54)
        for i, c in enumerate([1, 2, 5]):
            g = (label_map == c).astype(np.float64)
            if tau > 0:
                r = int(np.ceil(6 * tau))
                t = np.abs(np.arange(-r, r + 1)) / tau
                kernel = np.exp(-t) / (1 + np.exp(-t)) ** 2
                kernel /= kernel.sum()
                p = np.pad(g, r, mode="edge")
                p = np.stack([np.convolve(col, kernel, mode="valid") for col in p.T], 1)  # along y
                g = np.stack([np.convolve(row, kernel, mode="valid") for row in p], 0)  # along x
            want = np.zeros((38, 54))
            want[1:, 1:] = g.cumsum(0).cumsum(1)
            np.testing.assert_allclose(got[i], want, rtol=0, atol=1e-9)


def _reference_box_integrals(tables, index, boxes):
    """The bilinear lookups as plain torch operations (the implementation before the numpy one)."""
    _, hp, wp = tables.shape
    xs = torch.stack([boxes[:, 0], boxes[:, 2]], 1).clamp(0, wp - 1)
    ys = torch.stack([boxes[:, 1], boxes[:, 3]], 1).clamp(0, hp - 1)
    xi = xs.detach().floor().clamp(max=wp - 2).long()
    yi = ys.detach().floor().clamp(max=hp - 2).long()
    fx, fy = (xs - xi)[:, None, :], (ys - yi)[:, :, None]
    c, x, y = index[:, None, None], xi[:, None, :], yi[:, :, None]
    v = (tables[c, y, x] * (1 - fx) * (1 - fy) + tables[c, y, x + 1] * fx * (1 - fy)
         + tables[c, y + 1, x] * (1 - fx) * fy + tables[c, y + 1, x + 1] * fx * fy)
    return v[:, 1, 1] - v[:, 1, 0] - v[:, 0, 1] + v[:, 0, 0]


def test_box_integrals_equal_torchs_autograd_of_the_lookups():
    rng = np.random.default_rng(4)
    label_map = rng.choice(np.array([1, 2, 3], dtype=np.uint8), size=(41, 67))
    tables = smoothed_integrals(label_map, [1, 2, 3], 1.0)
    _, hp, wp = tables.shape
    n = 60
    boxes = torch.from_numpy(np.stack([rng.uniform(-5, wp + 5, n), rng.uniform(-5, hp + 5, n),
                                       rng.uniform(-5, wp + 5, n), rng.uniform(-5, hp + 5, n)], 1))
    boxes[:4] = torch.tensor([[0.0, 0.0, wp - 1, hp - 1], [3.0, 7.0, 20.0, 30.0], [wp - 1, 2.5, wp - 1, hp - 1.0],
                              [-1.0, hp - 1, 10.5, hp + 2.0]], dtype=torch.float64)  # on the bounds, on whole pixels
    index = torch.from_numpy(rng.integers(0, 3, n))
    a = boxes.clone().requires_grad_(True)
    b = boxes.clone().requires_grad_(True)
    got = box_integrals(tables, index, a)
    want = _reference_box_integrals(tables, index, b)
    torch.testing.assert_close(got, want, rtol=0, atol=1e-9)
    weights = torch.from_numpy(rng.normal(size=n))
    (got * weights).sum().backward()
    (want * weights).sum().backward()
    torch.testing.assert_close(a.grad, b.grad, rtol=0, atol=1e-9)


def test_the_tables_of_a_label_map_are_made_once_for_its_sizings():
    from facaid.sizing import cached_integrals

    label_map = np.zeros((40, 30), dtype=np.int64)
    label_map[5:15, 4:20] = 2
    first = cached_integrals(label_map, [0, 2], 1.0)
    assert cached_integrals(label_map.copy(), [0, 2], 1.0) is first  # the same pixels: the same tables
    assert torch.equal(first, smoothed_integrals(label_map, [0, 2], 1.0))
    other = label_map.copy()
    other[20, 20] = 2
    assert cached_integrals(other, [0, 2], 1.0) is not first
    assert cached_integrals(label_map, [0, 2], 0.0) is not first  # another edge width
