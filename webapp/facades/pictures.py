"""A procedure's pictures kept in storage: its label map (``labels.png``, at most 2,048 px a side) and the
gallery card's thumbnail (``thumbnail.png``, at most 320 px), rendered when a save of the procedure commits and
served as files. A picture is named by a digest of the tree it shows, so it never outlives an edit; one missing
(a procedure saved before pictures were kept, or a failed render) is rendered on its first request and kept.

Files are written whole or not at all (a temporary name, then a rename), and the pictures a save leaves behind
are decided from the tree the database holds once it commits, so saves racing each other keep the last one's."""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import uuid

from django.core.files.base import ContentFile
from django.core.files.storage import default_storage
from django.db import transaction

from webapp.facades import rendering

log = logging.getLogger(__name__)

SIDES = {"labels.png": rendering.MAX_RENDER_SIDE, "thumbnail.png": 320}


def digest(data: dict) -> str:
    """16 hex digits naming a procedure JSON (its keys sorted)."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _folder(code) -> str:
    return f"pictures/{code}"


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

    return rendering.label_map_png(to_segmentation(Tree.from_dict(data)), SIDES[kind])


def stored(proc, kind: str) -> tuple[str, str, bytes | None]:
    """(storage name, digest, the PNG when this call had to draw it) of the procedure's picture ``kind``. Its
    tree is read only to draw it, together with the digest it is filed under (an edit may have committed since
    ``proc`` was read); `LookupError` when the procedure is gone meanwhile. A picture that cannot be kept (a full
    disk) is logged and still returned."""
    name = f"{_folder(proc.code)}/{proc.digest}-{kind}"
    if proc.digest and default_storage.exists(name):
        return name, proc.digest, None
    from webapp.facades.models import Procedure

    row = Procedure.objects.filter(id=proc.id).values_list("digest", "data").first()
    if row is None:
        raise LookupError(f"procedure {proc.code} is gone")
    tag, data = row
    tag = tag or digest(data)
    name = f"{_folder(proc.code)}/{tag}-{kind}"
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


def _current(procedure_id: int) -> tuple | None:
    from webapp.facades.models import Procedure

    return Procedure.objects.filter(id=procedure_id).values_list("code", "digest", "data").first()


def refresh(procedure_id: int) -> None:
    """Give the procedure the pictures of the tree the database holds now, then delete those of other trees,
    judged again just before (a later save may have committed meanwhile; its refresh draws its own). A failure is
    logged and left to the first request, never raised into the save that committed."""
    try:
        row = _current(procedure_id)
        if row is None:
            return
        code, tag, data = row
        tag = tag or digest(data)
        for kind in SIDES:
            name = f"{_folder(code)}/{tag}-{kind}"
            if not default_storage.exists(name):
                _write(name, render(data, kind))
        latest = _current(procedure_id)
        keep = {tag, latest[1] if latest else tag}
        for name in _files(code):
            if name.rsplit("/", 1)[1].split("-", 1)[0] not in keep and not name.endswith(".partial"):
                default_storage.delete(name)
    except Exception:
        log.exception("could not render the pictures of procedure %s", procedure_id)


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

    from webapp.facades.models import Procedure

    post_save.connect(_saved, sender=Procedure, dispatch_uid="facaid-pictures-saved")
    post_delete.connect(_deleted, sender=Procedure, dispatch_uid="facaid-pictures-deleted")
