"""A procedure's pictures kept in storage: its label map (``labels.png``, at most 2,048 px a side) and the
gallery card's thumbnail (``thumbnail.png``, at most 320 px), rendered when the procedure is saved and served as
files. A picture is named by a digest of the tree it shows, so it never outlives an edit; one missing (a
procedure saved before pictures were kept, or a failed render) is rendered on its first request and kept."""

from __future__ import annotations

import hashlib
import json
import logging

from django.core.files.base import ContentFile
from django.core.files.storage import default_storage

from webapp.facades import rendering

log = logging.getLogger(__name__)

SIDES = {"labels.png": rendering.MAX_RENDER_SIDE, "thumbnail.png": 320}


def digest(data: dict) -> str:
    """16 hex digits naming a procedure JSON (its keys sorted)."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _folder(proc) -> str:
    return f"pictures/{proc.code}"


def stored(proc, kind: str) -> tuple[str, str]:
    """(storage name, digest) of the procedure's picture ``kind``, rendered and saved first if missing."""
    from facaid.grammar import Procedure as Tree
    from facaid.grammar import to_segmentation

    tag = digest(proc.data)
    name = f"{_folder(proc)}/{tag}-{kind}"
    if not default_storage.exists(name):
        png = rendering.label_map_png(to_segmentation(Tree.from_dict(proc.data)), SIDES[kind])
        saved = default_storage.save(name, ContentFile(png))
        if saved != name:  # another request saved the same picture meanwhile: keep one
            default_storage.delete(saved)
    return name, tag


def _others(proc, keep: set[str]) -> list[str]:
    folder = _folder(proc)
    if not default_storage.exists(folder):
        return []
    return [f"{folder}/{f}" for f in default_storage.listdir(folder)[1] if f"{folder}/{f}" not in keep]


def refresh(proc) -> None:
    """Render what the procedure's current tree lacks and delete the pictures of its earlier trees. A failure
    is logged and left to the first request, never raised into the save that called this."""
    try:
        keep = {stored(proc, kind)[0] for kind in SIDES}
        for name in _others(proc, keep):
            default_storage.delete(name)
    except Exception:
        log.exception("could not render the pictures of procedure %s", proc.code)


def remove(proc) -> None:
    for name in _others(proc, set()):
        default_storage.delete(name)


def _saved(sender, instance, update_fields=None, raw=False, **_) -> None:
    if raw or (update_fields is not None and "data" not in update_fields):
        return
    refresh(instance)


def _deleted(sender, instance, **_) -> None:
    remove(instance)


def connect() -> None:
    """Keep pictures in step with every save and delete of a procedure, wherever it happens (the site, the
    worker, the admin)."""
    from django.db.models.signals import post_delete, post_save

    from webapp.facades.models import Procedure

    post_save.connect(_saved, sender=Procedure, dispatch_uid="facaid-pictures-saved")
    post_delete.connect(_deleted, sender=Procedure, dispatch_uid="facaid-pictures-deleted")
