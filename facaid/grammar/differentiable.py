"""The differentiable executor: leaf boxes as a torch function of the sizing parameters.

A `Plan` is compiled once per procedure structure (repeat counts resolved, mirrors expanded). Executing it
runs one batch of tensor operations per tree level, so its cost grows with the depth, not the number of
rectangles, and gradients reach every parameter, shared ones (repeated patterns, mirrored halves) included.
"""

from __future__ import annotations

from dataclasses import dataclass

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


def _split_level(lv: Level, boxes: torch.Tensor, params: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    pb = boxes[lv.parent]  # (N, 4)
    lo = torch.where(lv.is_y, pb[:, 1], pb[:, 0])
    hi = torch.where(lv.is_y, pb[:, 3], pb[:, 2])
    length = hi - lo
    v = params[lv.param]
    zero = torch.zeros_like(v)
    fixed = torch.where(lv.mode == _ABS, v, torch.where(lv.mode == _REL, v * length, zero))
    weight = torch.where(lv.mode == _FLT, v, zero)
    n_groups = lv.group_first.shape[0]
    fixed_sum = torch.zeros(n_groups, dtype=v.dtype, device=v.device).index_add(0, lv.group, fixed)[lv.group]
    weight_sum = torch.zeros(n_groups, dtype=v.dtype, device=v.device).index_add(0, lv.group, weight)[lv.group]
    ratio = length / fixed_sum.clamp_min(_EPS)
    has_float = weight_sum > 0
    scale = torch.where(has_float, ratio.clamp(max=1.0), ratio)
    share = (length - fixed_sum).clamp_min(0.0) / weight_sum.clamp_min(_EPS)
    seg = torch.where(lv.mode == _FLT, weight * share, fixed * scale)  # (N,)
    before = torch.cumsum(seg, 0) - seg
    offset = before - before[lv.group_first][lv.group]
    a = torch.where(lv.flip, hi - offset - seg, lo + offset)
    b = a + seg
    x0 = torch.where(lv.is_y, pb[:, 0], a)
    y0 = torch.where(lv.is_y, a, pb[:, 1])
    x1 = torch.where(lv.is_y, pb[:, 2], b)
    y1 = torch.where(lv.is_y, b, pb[:, 3])
    # how far fixed sizes overflow a node that has floating children (there the fixed ones are scaled down
    # and stop responding to their own values: an optimizer is steered back with this)
    first = lv.group_first
    overflow = torch.where(has_float[first], (fixed_sum[first] - length[first]).clamp_min(0.0), 0.0).sum()
    return torch.stack([x0, y0, x1, y1], dim=1), overflow  # (N, 4), ()


def execute_plan(plan: Plan, params: torch.Tensor | None = None, *, with_overflow: bool = False):
    """Leaf boxes (L, 4) as (x0, y0, x1, y1), depth-first like `execute`, differentiable in ``params``.

    With ``with_overflow``, also the total length (pixels) by which fixed sizes overflow nodes that have
    floating children: zero for a procedure whose sizes all take effect."""
    if params is None:
        params = plan.values
    root = torch.tensor([[0.0, 0.0, plan.width, plan.height]], dtype=params.dtype, device=params.device)
    boxes = [root]
    overflow = torch.zeros((), dtype=params.dtype, device=params.device)
    for lv in plan.levels:
        level_boxes, level_overflow = _split_level(lv, boxes[-1], params)
        boxes.append(level_boxes)
        overflow = overflow + level_overflow
    flat = torch.cat(boxes, 0)
    starts = torch.tensor([0] + [b.shape[0] for b in boxes[:-1]], device=flat.device).cumsum(0)
    leaves = flat[starts[plan.leaf_level] + plan.leaf_index]
    return (leaves, overflow) if with_overflow else leaves


def execute_torch(proc: Procedure, params: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """Compile and execute: (labels (L,), boxes (L, 4))."""
    plan = compile_plan(proc)
    return plan.labels, execute_plan(plan, params)
