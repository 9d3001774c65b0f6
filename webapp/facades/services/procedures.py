"""Procedures: one stored from a procedure JSON, forked (a private copy with its parent named), and re-run against
the segmentation it was made from (a job). Their versions, edits and comparisons: `versions`. Bad input raises
`Invalid` naming the field."""

from __future__ import annotations

from collections.abc import Callable

from facaid.defaults import DEFAULT_K
from webapp.facades import access
from webapp.facades.errors import Invalid
from webapp.facades.models import Change, Job, Procedure, ProcedureVersion
from webapp.facades.services.jobs import submit_job


def create_procedure(user, fields: dict) -> Procedure:
    """A procedure of ``user``'s from a validated procedure JSON (``data``) with its title and visibility."""
    if "data" not in fields:
        raise Invalid("a procedure JSON is required", "data")
    return Procedure.objects.create(owner=user, **fields)


def fork_procedure(user, proc: Procedure, data: dict | None = None, note: str = "",
                   measure: Callable[[Procedure], None] | None = None, title: str = "") -> Procedure:
    """A private copy owned by ``user`` with ``proc`` as its parent. It keeps the links to the photo and the
    segmentation, which show (the overlay, the re-run) only while the photo is shared with the viewer
    (`access.photo_visible_to`, checked on every view): once a private photo is shared, the fork shows it too. It
    keeps the procedure's own scale (its metres per pixel, which all who may see the procedure are shown:
    `disclosure`), so that it downloads at its parent's size. Its first version says where it came from ("forked
    from version 3 of “Street”"), or ``note``; with ``data`` (an edited tree or a variation), that tree is its
    first version, its figures made by ``measure`` (`versions.remeasure`). Titled ``title``, else "Fork of …"."""
    title = title or (proc.title if proc.title.startswith("Fork of") else f"Fork of {proc.title or 'procedure'}")
    current = proc.current_version()
    copy = Procedure(
        owner=user, title=title[:200], data=proc.data if data is None else data, parent=proc,
        accuracy=proc.accuracy, metrics=proc.metrics, photo=proc.photo, segmentation_id=proc.segmentation_id,
        metres_per_pixel=proc.metres_per_pixel, scale_from=proc.scale_from)
    if data is not None and measure is not None:
        measure(copy)
    copy.save(change=Change(ProcedureVersion.Kind.CREATED, note or (
        f"forked from version {current.version if current else 1} of “{proc.title or proc.code}”")))
    return copy


def rerun(user, proc: Procedure, nodes: int, k: int = DEFAULT_K) -> Job:
    """Re-run inference against the segmentation ``proc`` was made from, keeping its first ``nodes`` nodes (breadth
    first), for its owner ``user``; `Invalid` naming ``procedure`` without a segmentation ``user`` may see
    (none, or a fork's photo made private since the fork)."""
    if proc.segmentation_id is None:
        raise Invalid("this procedure has no segmentation to re-run against", "procedure")
    if not access.segmentation_visible_to(user, proc):
        raise Invalid("the photo this procedure was made from is not shared with you, so it cannot be re-run",
                      "procedure")
    return submit_job(user, proc.segmentation, k=k, seed=0, prefix=proc, prefix_nodes=nodes)
