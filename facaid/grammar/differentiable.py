"""The differentiable executor: leaf boxes as a torch function of the sizing parameters.

A `Plan` is compiled once per procedure structure (repeat counts resolved, mirrors expanded). Executing it
runs one batch of tensor operations per tree level, so its cost grows with the depth, not the number of
rectangles, and gradients reach every parameter, shared ones (repeated patterns, mirrored halves) included.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import torch

from facaid.grammar.execute import Trace, execute
from facaid.grammar.procedure import Procedure

_ABS, _REL, _FLT = 0, 1, 2
_MODE_CODE = {"abs": _ABS, "rel": _REL, "flt": _FLT}
_EPS = 1e-9


@dataclass
class Level:
    parent: torch.Tensor  # (N,) index into the previous level's boxes
    group: torch.Tensor  # (N,) index of the sibling group
    group_first: torch.Tensor  # (G,) index of each group's first child
    param: torch.Tensor  # (N,) index into the parameter vector
    mode: torch.Tensor  # (N,) 0 abs, 1 rel, 2 flt
    is_y: torch.Tensor  # (N,) bool: split along y
    flip: torch.Tensor  # (N,) bool: laid out from the far end


@dataclass
class Plan:
    width: float
    height: float
    levels: list[Level]
    leaf_level: torch.Tensor  # (L,) level of each leaf, depth-first order
    leaf_index: torch.Tensor  # (L,) index within that level
    labels: torch.Tensor  # (L,) label ids
    values: torch.Tensor  # (P,) the procedure's own parameters (float64)

    def to(self, device: torch.device | str) -> Plan:
        def mv(level: Level) -> Level:
            return Level(*(getattr(level, f).to(device) for f in Level.__dataclass_fields__))

        return Plan(self.width, self.height, [mv(lv) for lv in self.levels], self.leaf_level.to(device),
                    self.leaf_index.to(device), self.labels.to(device), self.values.to(device))

    @functools.cached_property
    def arrays(self) -> list[_LevelArrays]:
        """The levels' index arrays in numpy, for `execute_plan`; made on first use."""
        return [_LevelArrays(lv) for lv in self.levels]

    @functools.cached_property
    def leaf_rows(self) -> np.ndarray:
        """Each leaf's row among all levels' boxes stacked (the root's first), for `execute_plan`."""
        starts = np.cumsum([0, 1] + [len(lv.parent) for lv in self.levels[:-1]])
        return starts[self.leaf_level.cpu().numpy()] + self.leaf_index.cpu().numpy()


def compile_plan(proc: Procedure) -> Plan:
    """Resolve the structure of a procedure for differentiable execution."""
    trace = Trace()
    leaves = execute(proc, trace)
    n = len(trace.depth)
    local = [0] * n  # index within its level
    per_level: list[list[int]] = []
    for i in range(n):
        d = trace.depth[i]
        while len(per_level) <= d:
            per_level.append([])
        local[i] = len(per_level[d])
        per_level[d].append(i)
    levels = []
    for members in per_level[1:]:
        parents = [local[trace.parent[i]] for i in members]
        group, first = [], []
        for j, p in enumerate(parents):
            if j == 0 or p != parents[j - 1]:
                first.append(j)
            group.append(len(first) - 1)
        levels.append(Level(
            parent=torch.tensor(parents, dtype=torch.long),
            group=torch.tensor(group, dtype=torch.long),
            group_first=torch.tensor(first, dtype=torch.long),
            param=torch.tensor([trace.param[i] for i in members], dtype=torch.long),
            mode=torch.tensor([_MODE_CODE[trace.mode[i]] for i in members], dtype=torch.long),
            is_y=torch.tensor([trace.axis[i] == "y" for i in members], dtype=torch.bool),
            flip=torch.tensor([trace.flip[i] for i in members], dtype=torch.bool),
        ))
    return Plan(
        width=float(proc.width),
        height=float(proc.height),
        levels=levels,
        leaf_level=torch.tensor([trace.depth[i] for i in trace.leaves], dtype=torch.long),
        leaf_index=torch.tensor([local[i] for i in trace.leaves], dtype=torch.long),
        labels=torch.tensor([lab for lab, *_ in leaves], dtype=torch.long),
        values=torch.tensor(proc.parameters(), dtype=torch.float64),
    )


class _LevelArrays:
    """A level's index arrays in numpy, and what its backward pass needs of them."""

    def __init__(self, lv: Level):
        self.parent = lv.parent.cpu().numpy()
        self.group = lv.group.cpu().numpy()
        self.first = lv.group_first.cpu().numpy()
        self.last = np.append(self.first[1:], len(self.group)) - 1  # each group's last member
        self.param = lv.param.cpu().numpy()
        mode = lv.mode.cpu().numpy()
        self.is_abs, self.is_rel, self.is_flt = mode == _ABS, mode == _REL, mode == _FLT
        self.is_y = lv.is_y.cpu().numpy()
        self.flip = lv.flip.cpu().numpy()
        # columns of the parent box: along the split (lo, hi) and across it (kept)
        self.lo_col = np.where(self.is_y, 1, 0)
        self.hi_col = self.lo_col + 2
        self.across = np.stack([1 - self.lo_col, 3 - self.lo_col], 1)  # (N, 2): the other axis' columns
        self.rows = np.arange(len(self.group))


def _level_forward(a: _LevelArrays, parent_boxes: np.ndarray, params: np.ndarray):
    """One level's boxes (N, 4), its overflow, and the intermediates its backward pass reads."""
    pb = parent_boxes[a.parent]  # (N, 4)
    lo, hi = pb[a.rows, a.lo_col], pb[a.rows, a.hi_col]
    length = hi - lo
    v = params[a.param]
    fixed = np.where(a.is_abs, v, np.where(a.is_rel, v * length, 0.0))
    weight = np.where(a.is_flt, v, 0.0)
    fixed_sum = np.add.reduceat(fixed, a.first)[a.group]  # groups are contiguous runs
    weight_sum = np.add.reduceat(weight, a.first)[a.group]
    fixed_den = np.maximum(fixed_sum, _EPS)
    ratio = length / fixed_den
    has_float = weight_sum > 0
    scale = np.where(has_float, np.minimum(ratio, 1.0), ratio)
    room = length - fixed_sum
    weight_den = np.maximum(weight_sum, _EPS)
    share = np.maximum(room, 0.0) / weight_den
    seg = np.where(a.is_flt, weight * share, fixed * scale)
    before = np.cumsum(seg) - seg
    offset = before - before[a.first][a.group]
    start = np.where(a.flip, hi - offset - seg, lo + offset)
    boxes = np.empty_like(pb)
    boxes[a.rows, a.lo_col] = start
    boxes[a.rows, a.hi_col] = start + seg
    boxes[a.rows[:, None], a.across] = pb[a.rows[:, None], a.across]
    over = -room[a.first]  # fixed sizes beyond the node's length, where it has floating children
    overflow = float(np.where(has_float[a.first], np.maximum(over, 0.0), 0.0).sum())
    saved = (length, v, fixed, weight, fixed_sum, fixed_den, weight_sum, weight_den, ratio, has_float, room,
             share, scale, over)
    return boxes, overflow, saved


def _level_backward(a: _LevelArrays, saved, grad_boxes: np.ndarray, grad_overflow: float,
                    grad_params: np.ndarray, grad_parent: np.ndarray) -> None:
    """Accumulate one level's gradients into ``grad_params`` (P,) and ``grad_parent`` (M, 4), following the
    torch operations of the forward pass exactly (a clamp passes its gradient at its bound, as torch's)."""
    (length, v, fixed, weight, fixed_sum, fixed_den, weight_sum, weight_den, ratio, has_float, room, share,
     scale, over) = saved
    g_end = grad_boxes[a.rows, a.hi_col]
    g_start = grad_boxes[a.rows, a.lo_col] + g_end
    g_seg = g_end - np.where(a.flip, g_start, 0.0)
    g_lo = np.where(a.flip, 0.0, g_start)
    g_hi = np.where(a.flip, g_start, 0.0)
    g_offset = np.where(a.flip, -g_start, g_start)
    # offset_n sums seg_j over the earlier members j of its group: seg_j gets the later members' g_offset
    later = np.cumsum(g_offset[::-1])[::-1] - g_offset  # over every later member of the level
    g_seg = g_seg + later - later[a.last][a.group]
    g_share = np.where(a.is_flt, g_seg * weight, 0.0)
    g_weight = np.where(a.is_flt, g_seg * share, 0.0)
    g_fixed = np.where(a.is_flt, 0.0, g_seg * scale)
    g_scale = np.where(a.is_flt, 0.0, g_seg * fixed)
    g_ratio = np.where(has_float, g_scale * (ratio <= 1.0), g_scale)
    g_room = g_share * (room >= 0) / weight_den
    g_weight_sum = -g_share * np.maximum(room, 0.0) / weight_den**2 * (weight_sum >= _EPS)
    g_length = g_room + g_ratio / fixed_den
    g_fixed_sum = -g_room - g_ratio * length / fixed_den**2 * (fixed_sum >= _EPS)
    g_group_fixed = np.add.reduceat(g_fixed_sum, a.first)
    # the overflow reads the first member's room: -room = fixed_sum - length
    g_over = np.where(has_float[a.first] & (over >= 0), grad_overflow, 0.0)
    g_group_fixed = g_group_fixed + g_over
    g_length_first = -g_over
    g_length = g_length + np.bincount(a.first, g_length_first, minlength=len(a.group))
    g_fixed = g_fixed + g_group_fixed[a.group]
    g_weight = g_weight + np.add.reduceat(g_weight_sum, a.first)[a.group]
    g_v = g_weight * a.is_flt + g_fixed * np.where(a.is_abs, 1.0, np.where(a.is_rel, length, 0.0))
    g_length = g_length + np.where(a.is_rel, g_fixed * v, 0.0)
    g_lo = g_lo - g_length
    g_hi = g_hi + g_length
    grad_params += np.bincount(a.param, g_v, minlength=len(grad_params))
    g_pb = np.zeros_like(grad_boxes)
    g_pb[a.rows, a.lo_col] = g_lo
    g_pb[a.rows, a.hi_col] = g_hi
    g_pb[a.rows[:, None], a.across] = grad_boxes[a.rows[:, None], a.across]
    for col in range(4):
        grad_parent[:, col] += np.bincount(a.parent, g_pb[:, col], minlength=len(grad_parent))


class _Execute(torch.autograd.Function):
    """The executor on numpy arrays with a hand-written backward pass: a level is some 40 numpy operations
    of a microsecond or two, where torch's autograd spent 5-15 microseconds on each of as many operations
    and as many again backwards (sizing steps it a hundred times a facade)."""

    @staticmethod
    def forward(ctx, params: torch.Tensor, plan: Plan):
        p = params.detach().cpu().numpy().astype(np.float64)
        boxes = [np.array([[0.0, 0.0, plan.width, plan.height]])]
        saved, overflow = [], 0.0
        for a in plan.arrays:
            level_boxes, level_overflow, keep = _level_forward(a, boxes[-1], p)
            boxes.append(level_boxes)
            saved.append(keep)
            overflow += level_overflow
        leaves = np.concatenate(boxes, 0)[plan.leaf_rows]
        ctx.plan, ctx.saved, ctx.sizes, ctx.n_params = plan, saved, [len(b) for b in boxes], len(p)
        out = torch.from_numpy(leaves).to(device=params.device, dtype=params.dtype)
        return out, torch.tensor(overflow, dtype=params.dtype, device=params.device)

    @staticmethod
    def backward(ctx, grad_leaves: torch.Tensor, grad_overflow: torch.Tensor):
        flat = np.zeros((sum(ctx.sizes), 4))
        flat[ctx.plan.leaf_rows] = grad_leaves.detach().cpu().numpy()  # each leaf is a node of its own
        ends = np.cumsum(ctx.sizes)
        grads = [flat[e - n:e] for n, e in zip(ctx.sizes, ends, strict=True)]  # views, per level
        g_params = np.zeros(ctx.n_params)
        g_over = float(grad_overflow)
        for i in range(len(ctx.saved) - 1, -1, -1):
            _level_backward(ctx.plan.arrays[i], ctx.saved[i], grads[i + 1], g_over, g_params, grads[i])
        out = torch.from_numpy(g_params).to(device=grad_leaves.device, dtype=grad_leaves.dtype)
        return out, None


def execute_plan(plan: Plan, params: torch.Tensor | None = None, *, with_overflow: bool = False):
    """Leaf boxes (L, 4) as (x0, y0, x1, y1), depth-first like `execute`, differentiable in ``params``.

    With ``with_overflow``, also the total length (pixels) by which fixed sizes overflow nodes that have
    floating children: zero for a procedure whose sizes all take effect."""
    if params is None:
        params = plan.values
    leaves, overflow = _Execute.apply(params, plan)
    return (leaves, overflow) if with_overflow else leaves


def execute_torch(proc: Procedure, params: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """Compile and execute: (labels (L,), boxes (L, 4))."""
    plan = compile_plan(proc)
    return plan.labels, execute_plan(plan, params)
