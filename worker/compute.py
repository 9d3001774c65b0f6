"""What a job computes, on plain JSON-ready data. The model is loaded once per process (CUDA when present)
by `facaid.pipeline.default_model`."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from facaid.defaults import DEFAULT_K
from facaid.grammar import Procedure
from facaid.segmentation import Segmentation

Progress = Callable[[float, str], None]

# what a job's result says of its tree, kept in the procedure's metrics beside its accuracy
JOB_METRICS = ("accuracy_decoded", "iou", "timings", "source", "retried", "shortcut", "structure")


def reconstruct(segmentation: dict, checkpoint: str, *, k: int = DEFAULT_K, seed: int = 0,
                prefix: dict | None = None, prefix_nodes: int = 0, progress: Progress | None = None,
                structure: str = "editable") -> dict[str, Any]:
    """Segmentation JSON -> the result as the worker stores it: ``{"procedure": JSON, "accuracy", "structure",
    "metrics"}`` (``metrics``: what the result says of its tree, `JOB_METRICS`, kept beside its accuracy), and for a
    real facade the other of its two procedures (``structure`` names the one returned first) as ``"alternative"``
    in the same shape. The one place a `facaid.pipeline.Reconstruction` becomes JSON for a job.

    ``prefix`` (a procedure JSON) with ``prefix_nodes`` > 0 keeps that procedure's first nodes (BFS) and lets
    the model continue from them. ``progress(fraction, stage)`` hears of each stage: loading the model (the
    first job of a process imports torch and reads the weights, seconds), then `facaid.reconstruct`'s own stages
    in the fractions 0.2 to 1."""
    seg = Segmentation.from_dict(segmentation)
    if progress:
        progress(0.05, "loading the model")
    from facaid.decoding import prefix_from_procedure
    from facaid.pipeline import ReconstructOptions, default_model
    from facaid.pipeline import reconstruct as run

    model, tokenizer = default_model(checkpoint)
    prefix_ids = None
    if prefix is not None and prefix_nodes > 0:
        prefix_ids = prefix_from_procedure(tokenizer, Procedure.from_dict(prefix), prefix_nodes)
    stages = (lambda fraction, stage: progress(0.2 + 0.8 * fraction, stage)) if progress else None
    result = run(seg, ReconstructOptions(k=k, seed=seed, prefix=prefix_ids, structure=structure), model=model,
                 tokenizer=tokenizer, progress=stages)
    summary = result.to_dict()
    out = {"procedure": result.procedure.to_dict(), "accuracy": result.accuracy, "structure": result.structure,
           "metrics": {key: summary[key] for key in JOB_METRICS}}
    if result.alternative is not None:
        other = "exact" if result.structure == "editable" else "editable"
        out["alternative"] = {"procedure": result.alternative.to_dict(), "accuracy": result.alternative_accuracy,
                              "structure": other, "metrics": {"source": "induced" if other == "exact" else "lattice",
                                                              "structure": other}}
    if progress:
        progress(1.0, "done")
    return out
