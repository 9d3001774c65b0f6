"""A procedure's pictures kept in storage: its label map (``labels.png``, at most 2,048 px a side) and the
gallery card's thumbnail (``thumbnail.png``, at most 320 px), drawn (`drawing`) when a save of the procedure commits
and served as files. A picture is named by a digest of the tree it shows, so it never outlives an edit; one missing
(a procedure saved before pictures were kept, or a failed render) is rendered on its first request and kept.

Files are written whole or not at all (a temporary name, then a rename), and the pictures a save leaves behind
are decided from the tree the database holds once it commits, so saves racing each other keep the last one's."""

from __future__ import annotations

import contextlib
import logging
import os
import uuid

from django.core.files.base import ContentFile
from django.core.files.storage import default_storage
from django.db import transaction

from facaid.grammar.budget import work_budget
from webapp.facades import drawing
from webapp.facades.models import Procedure

log = logging.getLogger(__name__)

SIDES = {"labels.png": drawing.MAX_RENDER_SIDE, "thumbnail.png": 320}


def _folder(code) -> str:
    return f"pictures/{code}"


def _name(code, tag: str, kind: str) -> str:
    return f"{_folder(code)}/{tag}-{kind}"


def _tag(name: str) -> str:
    """The digest a kept picture's name holds (the inverse of `_name`)."""
    return name.rsplit("/", 1)[1].split("-", 1)[0]


def _local_path(name: str) -> str | None:
    try:
        return default_storage.path(name)
    except NotImplementedError:  # a storage without local files
        return None


def _write(name: str, png: bytes) -> None:
    """Store the picture whole: a reader finds all of it or nothing."""
    path = _local_path(name)
    if path is None:
        if not default_storage.exists(name):
            default_storage.save(name, ContentFile(png))
        return
    os.makedirs(os.path.dirname(path), exist_ok=True)
    partial = f"{path}.{uuid.uuid4().hex}.partial"
    with open(partial, "wb") as f:
        f.write(png)
    os.replace(partial, path)


def render(data: dict, kind: str) -> bytes:
    """The picture ``kind`` of a procedure JSON; raises `ProcedureError` for one that no longer validates."""
    from facaid.grammar import Procedure as Tree
    from facaid.grammar import to_segmentation

    return drawing.label_map_png(to_segmentation(Tree.from_dict(data)), SIDES[kind])


def stored(proc, kind: str, redraw: bool = False, draw: bool = True) -> tuple[str, str, bytes | None] | None:
    """(storage name, digest, the PNG when this call had to draw it) of the procedure's picture ``kind``; with
    ``redraw``, drawn even if kept (the kept file just went); without ``draw``, None where it would have to be
    drawn (the caller takes a heavy slot first). Its tree is read only to draw it, together with the digest it is
    filed under (an edit may have committed since ``proc`` was read); `LookupError` when the procedure is gone
    meanwhile. A picture that cannot be kept (a full disk) is logged and still returned."""
    name = _name(proc.code, proc.digest, kind)
    if not redraw and proc.digest and default_storage.exists(name):
        return name, proc.digest, None
    if not draw:
        return None
    row = Procedure.objects.filter(id=proc.id).values_list("digest", "data").first()
    if row is None:
        raise LookupError(f"procedure {proc.code} is gone")
    tag, data = row
    name = _name(proc.code, tag, kind)
    png = render(data, kind)
    try:
        _write(name, png)
    except OSError:
        log.exception("could not keep %s", name)
    return name, tag, png


def _files(code) -> list[str]:
    folder = _folder(code)
    if not default_storage.exists(folder):
        return []
    return [f"{folder}/{f}" for f in default_storage.listdir(folder)[1]]


def refresh(procedure_id: int) -> None:
    """Give the procedure the pictures of the tree the database holds now, then delete those of other trees,
    judged again just before (a later save may have committed meanwhile; its refresh draws its own). A failure is
    logged and left to the first request, never raised into the save that committed."""
    rows = Procedure.objects.filter(id=procedure_id)
    try:
        with work_budget(10**12):  # not the request's: drawing what it saved is bounded by the tree's own limit
            _refresh(rows)
    except Exception:
        log.exception("could not render the pictures of procedure %s", procedure_id)


def _refresh(rows) -> None:
    row = rows.values_list("code", "digest", "data").first()
    if row is None:
        return
    code, tag, data = row
    for kind in SIDES:
        name = _name(code, tag, kind)
        if not default_storage.exists(name):
            _write(name, render(data, kind))
    keep = {tag, rows.values_list("digest", flat=True).first() or tag}
    for name in _files(code):
        if _tag(name) not in keep and not name.endswith(".partial"):
            default_storage.delete(name)


def remove(code) -> None:
    try:
        for name in _files(code):
            default_storage.delete(name)
        path = _local_path(_folder(code))
        if path is not None:
            with contextlib.suppress(OSError):  # not empty (a render in flight) or already gone
                os.rmdir(path)
    except Exception:
        log.exception("could not delete the pictures of procedure %s", code)


def _saved(sender, instance, update_fields=None, raw=False, **_) -> None:
    if raw or (update_fields is not None and "data" not in update_fields):
        return
    procedure_id = instance.id
    transaction.on_commit(lambda: refresh(procedure_id))  # outside the write's lock, and only if it commits


def _deleted(sender, instance, **_) -> None:
    code = instance.code
    transaction.on_commit(lambda: remove(code))


def connect() -> None:
    """Keep pictures in step with every save and delete of a procedure, wherever it happens (the site, the
    worker, the admin)."""
    from django.db.models.signals import post_delete, post_save

    post_save.connect(_saved, sender=Procedure, dispatch_uid="facaid-pictures-saved")
    post_delete.connect(_deleted, sender=Procedure, dispatch_uid="facaid-pictures-deleted")
