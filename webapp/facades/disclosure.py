"""What a procedure shows a viewer who may not see its photo (anyone but the photo's owner while it is private, a
fork's owner included): the procedure itself, its tree, pictures and 3D models, which redraw the annotation (an
exact version reproduces it as drawn), its own scale (metres per pixel: the size in metres its 3D models have, which
a fork keeps), and nothing more of the photo or its segmentation. No figure measured against the segmentation (pixel
accuracy, per-class IoU, a re-run's warning, the accuracy a reconstruction writes into the tree's meta), no title or
note that repeats the photo's title, no photo or segmentation ID (`serializers`), and of a procedure without a scale
of its own, not the photo's real size (`downloads`). The procedure's owner sees it all where the photo is theirs or
shared with them, and everyone does once it is shared: the rule is checked on every request.

The scale is the procedure's, not the photo's (issue 67): set from the photo's real size when the procedure is made
by one who may see it, it is one number about how large the building is, which the tree already draws to the pixel,
not what the photo shows, where it was taken or what it is called; a fork keeps it, so that it downloads at its
parent's size, and its owner may change or clear it (``metres_per_pixel`` on the API). Whoever shares a procedure is
told that its size in metres is shown with it (`sharing.REDRAWS`)."""

from __future__ import annotations

import re

from webapp.facades import access
from webapp.facades.models import Procedure

# what a procedure's metrics say of its structure, not of its segmentation: all that such a viewer is shown of them
STRUCTURE_METRICS = ("source", "structure")
SEGMENTATION_META = ("accuracy",)  # what a reconstruction writes into the tree's meta about its segmentation
WITHHELD = "the photo it was made from is not shared with you"
UNNAMED_PHOTO = "a photo not shared with you"  # as the pages name such a photo (`templatetags.naming.photo_name`)


def hidden(user, proc: Procedure) -> bool:
    """Is ``proc`` made from a photo ``user`` may not see? Then this module's rules apply to what they are shown."""
    return proc.photo_id is not None and not access.photo_visible_to(user, proc.photo)


def _photo_title(proc: Procedure) -> str:
    return proc.photo.title.strip() if proc.photo_id is not None else ""


def title(user, proc: Procedure) -> str:
    """The procedure's title as ``user`` is shown it: one that repeats its private photo's title (the automatic ones
    do: a job titles its procedure with the photo's, forks, copies and re-runs add to it) is a neutral one."""
    photo_title = _photo_title(proc)
    if photo_title and photo_title.casefold() in proc.title.casefold() and hidden(user, proc):
        return f"Procedure {str(proc.code)[:8]}"
    return proc.title


def note(user, proc: Procedure, text: str) -> str:
    """A version's note as ``user`` is shown it: the private photo's title named as the pages name such a photo (a
    copy's note names the procedure it was saved from)."""
    photo_title = _photo_title(proc)
    if not photo_title or not text or not hidden(user, proc):
        return text
    return re.sub(re.escape(photo_title), UNNAMED_PHOTO, text, flags=re.IGNORECASE)


def metrics(stored: dict | None) -> dict:
    """A procedure's or a version's metrics as such a viewer is shown them: where its structure came from, and why
    there is no accuracy."""
    return {**{k: v for k, v in (stored or {}).items() if k in STRUCTURE_METRICS}, "unmeasured": WITHHELD}


def tree(data: dict) -> dict:
    """A procedure JSON as such a viewer is shown it: its meta without the reconstruction's accuracy."""
    meta = data.get("meta") if isinstance(data, dict) else None
    if not isinstance(meta, dict) or not any(k in meta for k in SEGMENTATION_META):
        return data
    return {**data, "meta": {k: v for k, v in meta.items() if k not in SEGMENTATION_META}}


def figures(user, proc: Procedure, accuracy: float | None, stored: dict | None, warning: str = "") -> dict:
    """``{"accuracy", "metrics", "warning"}`` of the procedure or one of its versions as ``user`` is shown them."""
    if hidden(user, proc):
        return {"accuracy": None, "metrics": metrics(stored), "warning": ""}
    return {"accuracy": accuracy, "metrics": stored or {}, "warning": warning}
