"""Issue 42's "model proposes, induction repairs": keep the regions where the model's sized structure fits, graft the
induced structure of the annotation into the regions where it does not. Evaluation on CMP dev facades only."""

from __future__ import annotations

import argparse
import json
import statistics
import time

import numpy as np

from facaid.augmentation import annotator_noise
from facaid.evaluation.real import load_records
from facaid.grammar.execute import execute_with_boxes, to_segmentation
from facaid.grammar.procedure import Procedure, ProcedureError
from facaid.reading.induce import induce_procedure
from facaid.metrics import compression, element_leaves, pixel_accuracy
from facaid.paths import DEFAULT_CMP
from facaid.pipeline import ReconstructOptions, default_model, reconstruct
from facaid.segmentation import Segmentation, flatten, rasterize
from facaid.sizing import fit_sizes


def crop(seg: Segmentation, box) -> Segmentation:
    x0, y0, x1, y1 = (int(round(v)) for v in box)
    rows = seg.to_array().astype(np.int64)
    rows[:, [1, 3]] = np.clip(rows[:, [1, 3]], x0, x1) - x0
    rows[:, [2, 4]] = np.clip(rows[:, [2, 4]], y0, y1) - y0
    rows = rows[(rows[:, 3] > rows[:, 1]) & (rows[:, 4] > rows[:, 2])]
    return Segmentation.from_array(max(1, x1 - x0), max(1, y1 - y0), rows)


class Repairer:
    def __init__(self, seg: Segmentation, margin: float, depth: int):
        self.seg, self.target = seg, rasterize(seg)
        self.margin, self.max_depth = margin, depth
        self.grafts = 0
        self.grafted_area = 0.0

    def region_accuracy(self, pred: np.ndarray, box) -> float:
        x0, y0, x1, y1 = (int(round(v)) for v in box)
        if x1 <= x0 or y1 <= y0:
            return 1.0
        return float((pred[y0:y1, x0:x1] == self.target[y0:y1, x0:x1]).mean())

    def induced(self, box):
        part = crop(self.seg, box)
        proc = induce_procedure(part)
        if proc is None:
            return None, 0.0
        return proc, pixel_accuracy(rasterize(to_segmentation(proc)), rasterize(part))

    def run(self, proc: Procedure) -> Procedure:
        out = Procedure(proc.width, proc.height, proc.root.copy(), dict(proc.meta))
        _, boxes = execute_with_boxes(out)
        pred = rasterize(to_segmentation(out))
        out.root = self.visit(out.root, boxes, pred, 0)
        return out

    def visit(self, node, boxes, pred, depth):
        box = boxes.get(id(node))
        if box is None:
            return node
        mine = self.region_accuracy(pred, box)
        graft, theirs = self.induced(box)
        if graft is None or theirs <= mine + self.margin:
            return node  # the model's region fits as well as the annotation's own structure, less a margin
        if node.rule == "split" and depth < self.max_depth:  # look for the parts that are wrong
            node.children = [self.visit(c, boxes, pred, depth + 1) for c in node.children]
            return node
        self.grafts += 1
        self.grafted_area += (box[2] - box[0]) * (box[3] - box[1])
        root = graft.root
        root.role = root.role or node.role
        return root


ap = argparse.ArgumentParser()
ap.add_argument("--every", type=int, default=9)
ap.add_argument("--margin", type=float, nargs="+", default=[0.01])
ap.add_argument("--depth", type=int, default=3)
ap.add_argument("--k", type=int, default=4)
ap.add_argument("--perturb", type=int)
ap.add_argument("--out")
args = ap.parse_args()
model, tok = default_model()
records = load_records(DEFAULT_CMP, 189)[:: args.every]
rows = []
for i, (rid, seg) in enumerate(records):
    flat = flatten(seg)
    target = rasterize(flat)
    given = seg if args.perturb is None else annotator_noise(seg, args.perturb * 100_003 + i * args.every)
    gflat = flatten(given)
    t0 = time.perf_counter()
    alone = reconstruct(gflat, ReconstructOptions(k=args.k, induce=False, retry_k=0), model=model, tokenizer=tok)
    t1 = time.perf_counter()
    induced = fit_sizes(induce_procedure(gflat), gflat).procedure
    t2 = time.perf_counter()
    row = {"id": rid, "model": pixel_accuracy(rasterize(to_segmentation(alone.procedure)), target),
           "model_c": compression(alone.procedure, given),
           "induced": pixel_accuracy(rasterize(to_segmentation(induced)), target),
           "induced_c": compression(induced, given), "t_model": t1 - t0, "t_induce": t2 - t1,
           "input": pixel_accuracy(rasterize(gflat), target)}
    for margin in args.margin:
        rep = Repairer(gflat, margin, args.depth)
        t3 = time.perf_counter()
        fixed = rep.run(alone.procedure)
        try:
            fixed = Procedure.from_dict(fixed.to_dict())
            sized = fit_sizes(fixed, gflat).procedure
        except ProcedureError as exc:
            print(rid, "invalid", exc)
            continue
        row[f"repair{margin}"] = pixel_accuracy(rasterize(to_segmentation(sized)), target)
        row[f"repair{margin}_c"] = compression(sized, given)
        row[f"repair{margin}_share"] = 1 - rep.grafted_area / (gflat.width * gflat.height)
        row[f"repair{margin}_t"] = time.perf_counter() - t3
        row[f"repair{margin}_leaves"] = element_leaves(sized)
    rows.append(row)
    print(json.dumps({k: (round(v, 3) if isinstance(v, float) else v) for k, v in row.items()}), flush=True)
for key in ["model", "induced", *[f"repair{m}" for m in args.margin]]:
    acc = [r[key] for r in rows if key in r]
    comp = [r[key + "_c"] for r in rows if key in r]
    extra = ""
    if key.startswith("repair"):
        extra = f", model's share of the area {100 * np.mean([r[key + '_share'] for r in rows if key in r]):.1f} %"
    print(f"{key}: {len(acc)} facades, accuracy {100 * np.mean(acc):.2f} %, compression median "
          f"{statistics.median(comp):.2f}{extra}")
if args.out:
    with open(args.out, "w") as f:
        for r in rows:
            f.write(json.dumps(r) + "\n")
