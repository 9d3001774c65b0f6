"""The sizing optimizer: fit a procedure's sizes so that executing it reproduces a target segmentation.

The structure stays fixed (repeat counts included). The differentiable executor gives every leaf's box as a
function of the sizes; a soft rasterizer gives every leaf sigmoid edges of width ``tau`` pixels; Adam
minimizes the per-class pixel MSE between that coverage and the target's one-hot label map. Because the leaves
tile the image, the MSE reduces to the overlap of each leaf with its own class in the target smoothed by the
sigmoid's profile, which summed-area tables give in closed form at full resolution (up to 1024 px), O(leaves)
per step. The edges sharpen stage by stage (``taus``), and a stage stops when the loss no longer improves.
Sizes are optimized in log space (abs, flt) or logit space (rel), so they stay valid.

Pixel losses give no gradient to a box far from where it belongs, so the run starts with a direct fit of the
geometry: every element leaf is matched to the target rectangle of its class it overlaps most, and the
squared distances between matched edges are minimized (matches are renewed a few times, as in ICP). The
pixel loss then polishes what the matching cannot see.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
import torch

from facaid.grammar.differentiable import compile_plan, execute_plan
from facaid.grammar.guillotine import partition
from facaid.grammar.procedure import Procedure, ProcedureError
from facaid.labels import FACADE, LABELS
from facaid.metrics import procedure_accuracy, procedure_iou, scaled_label_map
from facaid.segmentation import Segmentation

_MIN = 1e-3
# Summed-area tables of the last few targets: a real facade is sized two or three times against the same label
# map (the exact procedure, then each lattice reading), and the tables take a third of a sizing's time.
_TABLES: OrderedDict[tuple, torch.Tensor] = OrderedDict()
_TABLES_KEPT = 2  # a facade's two edge widths: held between its sizings, 2 x up to 100 MB


@dataclass
class SizingResult:
    procedure: Procedure
    steps: int
    loss: float
    accuracy_before: float
    accuracy: float
    iou: dict[str, float]


def _modes(proc: Procedure) -> list[str]:
    return [s.mode for _, node in proc.nodes() for s in node.own_sizes()]


def _to_free(values: torch.Tensor, is_rel: torch.Tensor) -> torch.Tensor:
    rel = values.clamp(_MIN, 1 - _MIN)
    return torch.where(is_rel, torch.log(rel / (1 - rel)), torch.log(values.clamp_min(_MIN)))


def _from_free(free: torch.Tensor, is_rel: torch.Tensor) -> torch.Tensor:
    # clamped: a wild optimizer step must not leave the grammar's range (sizes up to 100,000 px)
    return torch.where(is_rel, torch.sigmoid(free), torch.exp(free.clamp(-12.0, 11.5)))


def smoothed_integrals(label_map: np.ndarray, classes: list[int], tau: float) -> torch.Tensor:
    """Summed-area tables (C, H + 1, W + 1), float64, of each listed class's indicator in ``label_map``,
    smoothed first by the logistic density of scale ``tau`` pixels along both axes (none when tau is 0).

    The integral of a smoothed indicator over a hard box equals the inner product of the indicator with the
    box's sigmoid-edged coverage (edges of width tau), so these tables evaluate the soft rasterizer's overlap
    with the target in closed form."""
    h, w = label_map.shape
    lm = torch.from_numpy(np.ascontiguousarray(label_map))
    g = (lm[None] == torch.tensor(classes, dtype=lm.dtype)[:, None, None]).double()  # (C, H, W)
    if tau > 0:
        r = int(np.ceil(6 * tau))
        t = np.abs(np.arange(-r, r + 1)) / tau
        kernel = np.exp(-t) / (1 + np.exp(-t)) ** 2
        kernel = (kernel / kernel.sum()).tolist()
        # edge-padded on both axes at once, then one axis at a time, each tap one in-place axpy over shifted
        # views (torch runs them on every core; numpy's per-tap temporaries cost 3x the time)
        padded = torch.nn.functional.pad(g[None], (r, r, r, r), mode="replicate")[0]
        rows = torch.zeros(len(classes), h, w + 2 * r, dtype=torch.float64)
        for j, k in enumerate(kernel):
            rows.add_(padded[:, j:j + h], alpha=k)
        g = torch.zeros_like(g)
        for j, k in enumerate(kernel):
            g.add_(rows[:, :, j:j + w], alpha=k)
    out = torch.zeros(len(classes), h + 1, w + 1, dtype=torch.float64)
    out[:, 1:, 1:] = g.cumsum(1).cumsum(2)
    return out


def cached_integrals(label_map: np.ndarray, classes: list[int], tau: float) -> torch.Tensor:
    """`smoothed_integrals`, kept for the last `_TABLES_KEPT` (label map, classes, edge width) asked for: the same
    tensor is handed out again, to be read only. Keyed by the map's bytes, so a map changed in place is a new key.
    The worker runs one job a process at a time; threads sharing the cache would need a lock."""
    digest = hashlib.blake2b(np.ascontiguousarray(label_map).view(np.uint8), digest_size=16).digest()
    key = (digest, label_map.shape, str(label_map.dtype), tuple(classes), float(tau))
    if key in _TABLES:
        _TABLES.move_to_end(key)
        return _TABLES[key]
    tables = smoothed_integrals(label_map, classes, tau)
    _TABLES[key] = tables
    while len(_TABLES) > _TABLES_KEPT:
        _TABLES.popitem(last=False)
    return tables


def forget_tables() -> None:
    """Let the kept tables go (`facaid.reconstruct` does at its end: up to 200 MB, not to be held between jobs)."""
    _TABLES.clear()


def box_integrals(tables: torch.Tensor, index: torch.Tensor, boxes: torch.Tensor) -> torch.Tensor:
    """For each box (L, 4: x0, y0, x1, y1 in table pixels), the integral of table ``index[l]`` over it.

    Bilinear in the summed-area table, which is exact for a piecewise-constant map: differentiable in the
    box edges at sub-pixel precision, O(L) per call whatever the image size. Computed in numpy with a
    hand-written gradient (`_BoxIntegrals`), the same as torch's autograd of the bilinear lookups."""
    return _BoxIntegrals.apply(boxes, tables, index)


class _BoxIntegrals(torch.autograd.Function):
    @staticmethod
    def forward(ctx, boxes: torch.Tensor, tables: torch.Tensor, index: torch.Tensor) -> torch.Tensor:
        t = tables.detach().cpu().numpy()
        _, hp, wp = t.shape
        b = boxes.detach().cpu().numpy().astype(np.float64)
        raw = b[:, [0, 2, 1, 3]].reshape(-1, 2, 2)  # (L, axis x|y, low|high edge)
        top = np.array([wp - 1, hp - 1])[None, :, None]
        edges = np.clip(raw, 0, top)
        cell = np.minimum(np.floor(edges), top - 1).astype(np.int64)
        f = edges - cell  # (L, 2, 2)
        c = index.detach().cpu().numpy()[:, None, None]
        x, y = cell[:, 0][:, None, :], cell[:, 1][:, :, None]  # (L, 1, 2 xs), (L, 2 ys, 1)
        t00, t01, t10, t11 = t[c, y, x], t[c, y, x + 1], t[c, y + 1, x], t[c, y + 1, x + 1]  # (L, 2 ys, 2 xs)
        fx, fy = f[:, 0][:, None, :], f[:, 1][:, :, None]
        v = t00 * (1 - fx) * (1 - fy) + t01 * fx * (1 - fy) + t10 * (1 - fx) * fy + t11 * fx * fy
        sign = np.array([[1.0, -1.0], [-1.0, 1.0]])  # v[1, 1] - v[1, 0] - v[0, 1] + v[0, 0]
        # d v / d x edge and d v / d y edge of each corner, signed; zero where the clamp held the edge
        inside = (raw >= 0) & (raw <= top)
        dx = (((t01 - t00) * (1 - fy) + (t11 - t10) * fy) * sign).sum(1) * inside[:, 0]  # (L, 2 xs)
        dy = (((t10 - t00) * (1 - fx) + (t11 - t01) * fx) * sign).sum(2) * inside[:, 1]  # (L, 2 ys)
        ctx.grad = np.stack([dx[:, 0], dy[:, 0], dx[:, 1], dy[:, 1]], 1)  # as the box's columns
        out = (v * sign).sum((1, 2))
        return torch.from_numpy(out).to(device=boxes.device, dtype=boxes.dtype)

    @staticmethod
    def backward(ctx, grad: torch.Tensor):
        g = torch.from_numpy(ctx.grad).to(device=grad.device, dtype=grad.dtype) * grad[:, None]
        return g, None, None


def fit_sizes(proc: Procedure, target: Segmentation, *, geometry_rounds: int = 2, geometry_steps: int = 20,
              geometry_lr: float = 1.0, polish_steps: int = 160, resolution: int = 1024, lr: float = 0.01,
              patience: int = 15, taus: tuple[float, ...] = (1.0, 0.0),
              device: str | torch.device = "cpu", before: float | None = None) -> SizingResult:
    """Fit the sizes of ``proc`` to ``target`` (same image size); returns the fitted procedure and figures.

    Two stages, each kept only if it raises the exact full-resolution pixel accuracy: the direct geometric
    fit, then ``polish_steps`` of Adam on the soft-rasterized pixel MSE at ``resolution`` (the raster's longer
    side). The result is never worse than the input. ``before``: ``procedure_accuracy(proc, target)`` when the
    caller has it already (it is computed otherwise).
    """
    if (round(proc.width), round(proc.height)) != (target.width, target.height):
        raise ValueError(f"procedure is {proc.width}x{proc.height} but the target is {target.width}x{target.height}")
    if before is None:
        before = procedure_accuracy(proc, target)
    modes = _modes(proc)
    if not modes:
        return SizingResult(proc, 0, 0.0, before, before, procedure_iou(proc, target))
    plan = compile_plan(proc).to(device)
    is_rel = torch.tensor([m == "rel" for m in modes], dtype=torch.bool, device=device)
    labels = plan.labels.to(device)
    best_proc, best_acc = proc, before
    free = _to_free(plan.values.to(device), is_rel).float().clone().requires_grad_(True)
    steps = 0
    if geometry_rounds:
        fit_geometry(plan, free, is_rel, labels, target, rounds=geometry_rounds, steps=geometry_steps, lr=geometry_lr)
        steps += geometry_rounds * geometry_steps
        candidate = _candidate(proc, free, is_rel)
        acc = procedure_accuracy(candidate, target) if candidate is not None else -1.0
        if acc > best_acc:
            best_proc, best_acc = candidate, acc
    loss = 0.0
    if polish_steps and best_acc < 1.0:
        free = _to_free(torch.tensor(best_proc.parameters(), dtype=torch.float64, device=device), is_rel)
        free = free.float().clone().requires_grad_(True)
        loss, done = _polish(plan, free, is_rel, labels, target, polish_steps, resolution, lr, patience, taus)
        steps += done
        candidate = _candidate(proc, free, is_rel)
        acc = procedure_accuracy(candidate, target) if candidate is not None else -1.0
        if acc > best_acc:
            best_proc, best_acc = candidate, acc
    return SizingResult(best_proc, steps, loss, before, best_acc, procedure_iou(best_proc, target))


def _candidate(proc: Procedure, free: torch.Tensor, is_rel: torch.Tensor) -> Procedure | None:
    """The procedure with the optimized sizes, or None if the optimizer left the valid range (NaN)."""
    try:
        return proc.with_parameters(_from_free(free.detach(), is_rel).double().cpu().tolist())
    except ProcedureError:
        return None


def _polish(plan, free: torch.Tensor, is_rel: torch.Tensor, labels: torch.Tensor, target: Segmentation,
            steps: int, resolution: int, lr: float, patience: int, taus: tuple[float, ...]) -> tuple[float, int]:
    """Adam on the per-class pixel MSE of the sigmoid-edged rasterization, one stage per edge width in
    ``taus`` (raster pixels, the last one sharp); leaves the best ``free`` of the last stage in place.

    The leaves tile the image, so the coverage's own square norm is constant (up to a term of order tau
    times the edge length) and the MSE is 1 - 2 <coverage, target> / (H W) + const: the overlap of every leaf
    with its class in the target, read from summed-area tables (`cached_integrals`, `box_integrals`)."""
    device = free.device
    scale = min(1.0, resolution / max(target.width, target.height))
    label_map = scaled_label_map(target, scale)
    h, w = label_map.shape
    classes = sorted(set(labels.tolist()))
    index = torch.zeros(len(LABELS), dtype=torch.long)
    index[classes] = torch.arange(len(classes))
    index = index.to(device)[labels]
    to_raster = torch.tensor([w / target.width, h / target.height] * 2, dtype=torch.float64, device=device)
    side = max(target.width, target.height)
    min_gain = 0.5 / (h * w)
    best = (float("inf"), free.detach().clone())
    done = 0
    per_stage = max(1, steps // len(taus))
    for stage, tau in enumerate(taus):
        tables = cached_integrals(label_map, classes, tau).to(device)
        last = stage == len(taus) - 1
        opt = torch.optim.Adam([free], lr=lr)
        stage_best, stale = float("inf"), 0
        for _ in range(per_stage):
            boxes, overflow = execute_plan(plan, _from_free(free, is_rel).double(), with_overflow=True)
            overlap = box_integrals(tables, index, boxes * to_raster).sum()
            loss = 2 * (1 - overlap / (h * w)) + 0.1 * overflow / side
            current = free.detach().clone()
            opt.zero_grad()
            loss.backward()
            opt.step()
            done += 1
            value = loss.item()
            if last and value < best[0]:
                best = (value, current)
            if value < stage_best - min_gain:  # a stage ends when a quarter pixel is no longer gained
                stage_best, stale = value, 0
            else:
                stale += 1
                if stale >= patience:
                    break
    with torch.no_grad():
        free.copy_(best[1])
    return best[0], done


def _target_rects(target: Segmentation) -> np.ndarray:
    """Rows (label, x0, y0, x1, y1) of the target's element and background rectangles (facade pieces left
    out: the wall is what the elements leave)."""
    rows = partition(target)
    return rows[rows[:, 0] != FACADE]


def _match(boxes: np.ndarray, labels: np.ndarray, rects: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each leaf with a label other than facade, the target rectangle of its label it overlaps most
    (IoU > 0). Returns (leaf indices, matched target boxes (M, 4))."""
    leaves, goals = [], []
    for lab in np.unique(labels):
        if lab == FACADE:
            continue
        li = np.flatnonzero(labels == lab)
        ti = np.flatnonzero(rects[:, 0] == lab)
        if len(ti) == 0:
            continue
        a = boxes[li][:, None, :]  # (P, 1, 4)
        b = rects[ti, 1:][None, :, :].astype(np.float64)  # (1, Q, 4)
        iw = np.clip(np.minimum(a[..., 2], b[..., 2]) - np.maximum(a[..., 0], b[..., 0]), 0, None)
        ih = np.clip(np.minimum(a[..., 3], b[..., 3]) - np.maximum(a[..., 1], b[..., 1]), 0, None)
        inter = iw * ih
        area_a = (a[..., 2] - a[..., 0]) * (a[..., 3] - a[..., 1])
        area_b = (b[..., 2] - b[..., 0]) * (b[..., 3] - b[..., 1])
        iou = inter / np.maximum(area_a + area_b - inter, 1e-9)  # (P, Q)
        best = iou.argmax(1)
        ok = iou[np.arange(len(li)), best] > 0
        leaves.append(li[ok])
        goals.append(b[0, best[ok]])
    if not leaves:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 4))
    return np.concatenate(leaves), np.concatenate(goals)


def fit_geometry(plan, free: torch.Tensor, is_rel: torch.Tensor, labels: torch.Tensor, target: Segmentation,
                 rounds: int = 4, steps: int = 30, lr: float = 1.0) -> None:
    """Direct fit: move ``free`` (in place) so that matched leaf edges land on their target edges."""
    rects = _target_rects(target)
    side = float(max(target.width, target.height))
    # L-BFGS, not Adam: Adam's normalized steps move sizes that no matched edge constrains as much as the
    # ones that are, and such sizes drift; with curvature, an unconstrained size keeps its decoded value
    opt = torch.optim.LBFGS([free], lr=lr, max_iter=steps, history_size=20, line_search_fn="strong_wolfe")
    lab = labels.cpu().numpy()
    for r in range(rounds):
        with torch.no_grad():
            boxes = execute_plan(plan, _from_free(free, is_rel).double()).cpu().numpy()
        idx, goal = _match(boxes, lab, rects)
        if len(idx) == 0:
            return
        # trimmed, as in ICP: an edge far from its match is not evidence (a pillar piece of one floor matched to
        # a pillar merged over all floors); the tolerance tightens from round to round
        mine = boxes[idx]
        extent = np.concatenate([mine[:, 2:] - mine[:, :2]] * 2, axis=1)  # (M, 4): w, h, w, h
        tolerance = np.maximum(3.0 if r == 0 else 1.5, extent * (0.35 if r == 0 else 0.1))
        weight = torch.from_numpy((np.abs(mine - goal) <= tolerance).astype(np.float64)).to(free.device)
        idx_t = torch.from_numpy(idx).to(free.device)
        goal_t = torch.from_numpy(goal).to(free.device)

        def closure(idx_t=idx_t, goal_t=goal_t, weight=weight) -> torch.Tensor:
            opt.zero_grad()
            all_boxes, overflow = execute_plan(plan, _from_free(free, is_rel).double(), with_overflow=True)
            err = (all_boxes[idx_t] - goal_t) / side
            loss = (err**2 * weight).sum() / weight.sum().clamp_min(1.0) + overflow / side * 1e-3
            loss.backward()
            return loss

        opt.step(closure)


