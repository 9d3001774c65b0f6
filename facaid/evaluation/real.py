"""Evaluation on real facades (the CMP annotations): `facaid evaluate-real`. For evaluation only.

Each record is read as layered rectangles (clipped to the image; degenerate boxes kept as the 1-pixel boxes
they are), flattened by the paint order, reconstructed (the model's structures and, where they fit badly, the
induced one; ``induce=False`` for the model alone), and compared at full resolution with its own label map.
The trivial baseline paints everything inside the building footprint as wall. Each facade's record gives the
structure that won (``source``; ``denoised`` where the model's was kept over a closer-fitting induced one,
`facaid.pipeline.reads_through_noise`) and the compression (`facaid.metrics.compression`); the figures come for all the
facades and for the dev half (the first 189 records) and the test half (the rest) apart. With ``perturb`` each
input is first annotated as a person would (`facaid.augmentation.annotator_noise`, seeded by ``perturb`` and the
facade's position) and both the reconstruction and the perturbed input itself are compared with the clean
annotation: how much the procedure reads through the noise.
"""

from __future__ import annotations

import json
import statistics
import time
from pathlib import Path

import numpy as np
from PIL import Image
from tqdm import tqdm

from facaid.augmentation import annotator_noise
from facaid.defaults import DEFAULT_K
from facaid.editing.describes import describes
from facaid.evaluation.editability import editability, kept_elements
from facaid.formats.render import colorize, side_by_side
from facaid.grammar.execute import to_segmentation
from facaid.labels import BACKGROUND, FACADE, LABELS
from facaid.metrics import compression, pixel_accuracy
from facaid.model import FacaidModel
from facaid.pipeline import ReconstructOptions, reconstruct
from facaid.reading.windows import segmentation_lattice
from facaid.segmentation import Segmentation, flatten, rasterize
from facaid.tokenizer import Tokenizer


def load_records(path: str | Path, limit: int | None = None, start: int = 0) -> list[tuple[str, Segmentation]]:
    """The records from ``start`` on (0-based), at most ``limit`` of them."""
    out = []
    with open(path, encoding="utf-8") as f:
        for i, line in enumerate(line for line in f if line.strip()):
            if i < start:
                continue
            rec = json.loads(line)
            out.append((rec.get("id", f"line{i + 1}"), Segmentation.from_dict(rec, clip=True)))
            if limit and len(out) >= limit:
                break
    return out


def all_wall(label_map: np.ndarray) -> np.ndarray:
    """The trivial baseline: every pixel of the building footprint is wall."""
    return np.where(label_map != BACKGROUND, FACADE, BACKGROUND).astype(np.uint8)


def evaluate_real(model: FacaidModel, tokenizer: Tokenizer, path: str | Path, *, k: int = DEFAULT_K,
                  limit: int | None = None, gallery: str | Path | None = None, gallery_count: int = 20,
                  progress: bool = True, induce: bool = True, perturb: int | None = None,
                  structure: str = "editable", start: int = 0) -> dict:
    records = load_records(path, limit, start)
    acc, acc_decoded, base, times = [], [], [], []
    inter = np.zeros(len(LABELS))
    union = np.zeros(len(LABELS))
    base_inter = np.zeros(len(LABELS))
    base_union = np.zeros(len(LABELS))
    pictures = []
    per_facade = []
    nodes = []
    for i, (rid, seg) in enumerate(tqdm(records, desc="evaluate-real", disable=not progress)):
        flat = flatten(seg)
        target = rasterize(flat)
        given = seg if perturb is None else annotator_noise(seg, perturb * 100_003 + i)
        given_flat = flat if perturb is None else flatten(given)
        t0 = time.perf_counter()
        result = reconstruct(given_flat, ReconstructOptions(k=k, induce=induce, structure=structure), model=model,
                             tokenizer=tokenizer)
        times.append(time.perf_counter() - t0)
        pred = rasterize(to_segmentation(result.procedure))
        trivial = all_wall(target)
        acc.append(pixel_accuracy(pred, target))
        acc_decoded.append(result.accuracy_decoded)
        base.append(pixel_accuracy(trivial, target))
        for c in range(len(LABELS)):
            t, p, b = target == c, pred == c, trivial == c
            inter[c] += (t & p).sum()
            union[c] += (t | p).sum()
            base_inter[c] += (t & b).sum()
            base_union[c] += (t | b).sum()
        nodes.append(sum(1 for _ in result.procedure.nodes()))
        record = {"id": rid, "half": "dev" if start + i < DEV_FACADES else "test", "accuracy": acc[-1],
                  "baseline": base[-1], "seconds": times[-1], "source": result.source, "shortcut": result.shortcut,
                  "denoised": result.denoised, "nodes": nodes[-1], "compression": compression(result.procedure, given),
                  "structure": result.structure, "lattice_seconds": result.timings.get("lattice", 0.0),
                  "group": result.procedure.meta.get("group"),
                  **editability(result.procedure, segmentation_lattice(seg)),
                  **describes(result.procedure, flat.to_array())}
        record["drawn"], record["kept"] = kept_elements(flat.to_array(), target, pred)
        if result.alternative is not None:  # the other structure, scored against the same target
            record["alternative_accuracy"] = pixel_accuracy(rasterize(to_segmentation(result.alternative)), target)
        if perturb is not None:  # the perturbed input's own accuracy against the clean annotation
            record["input_accuracy"] = pixel_accuracy(rasterize(given_flat), target)
        per_facade.append(record)
        if gallery is not None and i < gallery_count:
            pictures.append(side_by_side([colorize(target), colorize(pred)], height=200, gap=4))
    iou = {LABELS[c]: float(inter[c] / union[c]) for c in range(len(LABELS)) if union[c]}
    base_iou = {LABELS[c]: float(base_inter[c] / base_union[c]) for c in range(len(LABELS)) if base_union[c]}
    if gallery is not None and pictures:
        Path(gallery).parent.mkdir(parents=True, exist_ok=True)
        _grid(pictures, columns=4).save(gallery)
    return {
        "facades": len(records),
        "k": k,
        "structure": structure,
        "start": start,
        "induce": induce,
        "induced_share": float(np.mean([f["source"] in ("induced", "lattice") for f in per_facade]))
        if per_facade else 0.0,
        "shortcut_share": float(np.mean([f["shortcut"] for f in per_facade])) if per_facade else 0.0,
        "nodes_median": float(np.median(nodes)) if nodes else 0.0,
        "pixel_accuracy": {"mean": float(np.mean(acc)), "median": float(np.median(acc)),
                           "decoded_mean": float(np.mean(acc_decoded))},
        "baseline_all_wall": {"mean": float(np.mean(base)), "iou": base_iou},
        "iou": iou,
        "mean_iou": float(np.mean([iou[n] for n in iou if n != "background"])),
        "seconds_per_facade": {"median": statistics.median(times), "mean": float(np.mean(times))},
        "perturb": perturb,
        "summary": _summary(per_facade),
        "halves": {half: _summary([f for f in per_facade if f["half"] == half]) for half in ("dev", "test")},
        "per_facade": per_facade,
    }


DEV_FACADES = 189  # CMP facades 1-189: the dev half (looked at, aggregate statistics); the rest: the test half


def _summary(facades: list[dict]) -> dict:
    """The figures the targets name, for a group of facades: accuracy, compression, which structure won, and
    with a perturbation the accuracy of the perturbed input and the gain of the reconstruction over it."""
    if not facades:
        return {"facades": 0}
    out = {"facades": len(facades),
           "accuracy_mean": float(np.mean([f["accuracy"] for f in facades])),
           "compression_median": float(np.median([f["compression"] for f in facades])),
           "model_share": float(np.mean([f["source"].startswith("model") for f in facades])),
           "denoised_share": float(np.mean([f.get("denoised", False) for f in facades])),
           "seconds_median": float(np.median([f["seconds"] for f in facades]))}
    if "eligible" in facades[0]:  # the editability figures, over the facades with a lattice of windows
        eligible = [f for f in facades if f["eligible"]]
        out["eligible"] = len(eligible)
        for key in ("floors", "bays", "floors_plus_one", "bays_plus_one", "floors_clean", "bays_clean"):
            out[f"{key}_share"] = float(np.mean([f[key] for f in eligible])) if eligible else 0.0
        for key in ("floor_height_ok", "tile_width_ok"):  # over the facades with 3+ rows (columns) of windows
            judged = [f[key] for f in facades if f.get(key) is not None]
            out[f"{key}_share"] = float(np.mean(judged)) if judged else None
            out[f"{key}_judged"] = len(judged)
    if "drawn" in facades[0]:
        out["elements_drawn"] = int(sum(f["drawn"] for f in facades))
        out["elements_kept_share"] = float(sum(f["kept"] for f in facades) / max(1, out["elements_drawn"]))
        out["nothing_lost_share"] = float(np.mean([f["kept"] == f["drawn"] for f in facades]))
        out["lattice_seconds_median"] = float(np.median([f["lattice_seconds"] for f in facades]))
    if any("alternative_accuracy" in f for f in facades):
        out["alternative_accuracy_mean"] = float(np.mean(
            [f.get("alternative_accuracy", f["accuracy"]) for f in facades]))
    if "input_accuracy" in facades[0]:
        out["input_accuracy_mean"] = float(np.mean([f["input_accuracy"] for f in facades]))
        out["gain_over_input"] = out["accuracy_mean"] - out["input_accuracy_mean"]
    return out


def _grid(images: list[Image.Image], columns: int) -> Image.Image:
    rows = [side_by_side(images[i : i + columns], height=images[0].height, gap=6)
            for i in range(0, len(images), columns)]
    width = max(r.width for r in rows)
    out = Image.new("RGB", (width, sum(r.height for r in rows)), (255, 255, 255))
    y = 0
    for r in rows:
        out.paste(r, (0, y))
        y += r.height
    return out


def format_summary(result: dict) -> str:
    lines = [
        f"{result['facades']} CMP facades, best of {result['k']}, the {result.get('structure', 'editable')} procedure"
        + ("" if result.get("perturb") is None else
           f", inputs perturbed as people annotate (seed {result['perturb']})"),
        f"pixel accuracy: mean {100 * result['pixel_accuracy']['mean']:.2f} % (median "
        f"{100 * result['pixel_accuracy']['median']:.2f} %; before sizing "
        f"{100 * result['pixel_accuracy']['decoded_mean']:.2f} %); all-wall baseline "
        f"{100 * result['baseline_all_wall']['mean']:.2f} %",
        f"mean IoU over the 11 building classes: {100 * result['mean_iou']:.1f} %",
        f"seconds per facade: median {result['seconds_per_facade']['median']:.2f}",
        f"structure: induced (or read as floors of tiles) for {100 * result['induced_share']:.1f} % of the facades"
        + ("" if result["induce"] else " (induction off: the model alone)")
        + f", alone (the decoded one far behind, not sized) for {100 * result.get('shortcut_share', 0.0):.1f} %"
        + f"; median {result['nodes_median']:.0f} nodes per procedure",
    ]
    for name, group in (("all", result["summary"]), *result["halves"].items()):
        if not group.get("facades"):
            continue
        line = (f"{name}: {group['facades']} facades, accuracy {100 * group['accuracy_mean']:.2f} %, compression "
                f"median {group['compression_median']:.2f}, the model's structure for "
                f"{100 * group['model_share']:.1f} %"
                + (f" (kept over the induced copy of the input's noise for {100 * group['denoised_share']:.1f} %)"
                   if group.get("denoised_share") else ""))
        if "eligible" in group:
            share = {k: f"{100 * group[f'{k}_share']:.0f} %" for k in ("floors", "bays", "floors_plus_one",
                                                                         "bays_plus_one")}
            line += (f"; of {group['eligible']} with 2+ rows and columns of windows: floors {share['floors']}, bays "
                     f"{share['bays']}, floors + 1 works {share['floors_plus_one']}, bays + 1 {share['bays_plus_one']}"
                     f" (counting window rows); clean as a person looks: floors + 1 "
                     f"{100 * group['floors_clean_share']:.1f} %, bays + 1 {100 * group['bays_clean_share']:.1f} %")
            for key, what in (("floor_height_ok", "floor_height within 15 % of the floors' pitch"),
                              ("tile_width_ok", "tile_width the bays' pitch")):
                if group.get(f"{key}_share") is not None:
                    line += f"; {what} {100 * group[f'{key}_share']:.0f} % of {group[f'{key}_judged']}"
        if "elements_kept_share" in group:
            line += (f"; elements kept {100 * group['elements_kept_share']:.1f} % of {group['elements_drawn']}, "
                     f"nothing lost on {100 * group['nothing_lost_share']:.0f} % of the facades")
        if "alternative_accuracy_mean" in group:
            line += f"; the other structure {100 * group['alternative_accuracy_mean']:.2f} %"
        if "input_accuracy_mean" in group:
            line += (f"; the perturbed input itself {100 * group['input_accuracy_mean']:.2f} % against the clean "
                     f"annotation (gain {100 * group['gain_over_input']:+.2f} points)")
        lines.append(line)
    lines.append(f"{'class':<11} {'IoU':>7} {'baseline':>9}")
    for name, v in result["iou"].items():
        lines.append(f"{name:<11} {100 * v:>6.1f}% {100 * result['baseline_all_wall']['iou'].get(name, 0.0):>8.1f}%")
    return "\n".join(lines)
