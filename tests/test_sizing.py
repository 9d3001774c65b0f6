import pytest
import torch

from facaid.generator import generate
from facaid.grammar import Node, Procedure, Size
from facaid.grammar.differentiable import compile_plan, execute_plan
from facaid.labels import LABELS
from facaid.metrics import procedure_accuracy, scaled_label_map
from facaid.segmentation import Segmentation
from facaid.sizing import fit_sizes, soft_coverage
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


def test_soft_coverage_agrees_with_the_hard_label_map():
    s = generate(2)
    plan = compile_plan(s.procedure)
    scale = 64 / max(s.procedure.width, s.procedure.height)
    w, h = round(s.procedure.width * scale), round(s.procedure.height * scale)
    boxes = execute_plan(plan).float() * torch.tensor([w / s.procedure.width, h / s.procedure.height] * 2)
    cover = soft_coverage(boxes, plan.labels, w, h, tau=0.05)
    assert cover.shape == (len(LABELS), h, w)
    hard = torch.from_numpy(scaled_label_map(s.segmentation, scale).astype("int64"))
    assert float((cover.argmax(0) == hard).float().mean()) > 0.97
    assert float((cover.sum(0) - 1).abs().median()) < 0.01  # the leaves partition the image


def test_size_mismatch_is_an_error():
    s, q = quantized(1)
    small = Segmentation(10, 10, ())
    with pytest.raises(ValueError, match="but the target is 10x10"):
        fit_sizes(q, small)


def test_soft_coverage_per_class_products_equal_the_one_hot_formulation():
    s = generate(5)
    plan = compile_plan(s.procedure)
    boxes = (execute_plan(plan).float() * 0.1).requires_grad_(True)
    w, h = round(s.procedure.width * 0.1), round(s.procedure.height * 0.1)
    cover = soft_coverage(boxes, plan.labels, w, h, tau=0.5)
    u, v = torch.arange(w) + 0.5, torch.arange(h) + 0.5
    ref_boxes = boxes.detach().clone().requires_grad_(True)
    mx = torch.sigmoid((u - ref_boxes[:, :1]) / 0.5) * torch.sigmoid((ref_boxes[:, 2:3] - u) / 0.5)
    my = torch.sigmoid((v - ref_boxes[:, 1:2]) / 0.5) * torch.sigmoid((ref_boxes[:, 3:4] - v) / 0.5)
    onehot = torch.nn.functional.one_hot(plan.labels, len(LABELS)).float()
    ref = torch.einsum("lc,lh,lw->chw", onehot, my, mx)
    assert torch.allclose(cover, ref, atol=1e-5)
    weights = torch.rand_like(ref)
    (cover * weights).sum().backward()
    (ref * weights).sum().backward()
    assert torch.allclose(boxes.grad, ref_boxes.grad, atol=1e-4)
