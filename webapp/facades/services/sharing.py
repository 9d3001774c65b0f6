"""Sharing a procedure and its photo. A procedure and the photo it was made from each keep their own visibility:
a viewer sees the photo and the overlay only where the photo is shared with them (`access.photo_visible_to`,
checked every time, so a fork shows the overlay once its photo is shared, and never while it is private). When a
procedure is shared, its owner may share the photo with it, where the photo is theirs, and is told what viewers
will see: without the photo, still the procedure, which itself redraws the annotation."""

from __future__ import annotations

import copy

from django.db import transaction

from webapp.facades import access
from webapp.facades.errors import Invalid
from webapp.facades.models import Procedure, Visibility

REACH = {Visibility.PRIVATE: 0, Visibility.UNLISTED: 1, Visibility.PUBLIC: 2}
# what a procedure shared without its photo still tells of it (`disclosure`): the sharing question says so plainly
REDRAWS = ("The procedure itself redraws the annotation (an exact version reproduces it as drawn) at its size in "
           "metres; the photo's title and the accuracy against it are not shown.")


def _shared_as(photo_visibility: str, visibility: str) -> str:
    """The photo's visibility once shared with a procedure of ``visibility``: at least as wide, never narrower."""
    return visibility if REACH[photo_visibility] < REACH[visibility] else photo_visibility


def photo_shared(proc: Procedure) -> bool | None:
    """Whether all who may see the procedure, its owner included, see its photo and overlay too; None without a
    photo. An unlisted photo is seen by anyone with a link to it, and the procedure's page gives that link."""
    photo = proc.photo
    if photo is None:
        return None
    return access.photo_visible_to(proc.owner, photo) and (
        proc.visibility == Visibility.PRIVATE or photo.visibility in access.READABLE)


def may_share_photo(user, proc: Procedure) -> bool:
    """Is the procedure's photo ``user``'s and not public, so that sharing the procedure may share it too?"""
    return (user.is_authenticated and proc.photo is not None and proc.photo.owner_id == user.id
            and proc.photo.visibility != Visibility.PUBLIC)


def viewers_see(proc: Procedure) -> str:
    """What others see of the procedure and its photo, said to its owner."""
    if proc.visibility == Visibility.PRIVATE:
        return "Only you see this procedure."
    who = "Anyone" if proc.visibility == Visibility.PUBLIC else "Anyone with its link"
    photo = proc.photo
    if photo is None:
        return f"{who} sees the procedure, its pictures and 3D models; it has no photo."
    if photo_shared(proc):
        listed = " (the photo is unlisted: its page is not in the gallery)" if (
            photo.visibility == Visibility.UNLISTED and proc.visibility == Visibility.PUBLIC) else ""
        return f"{who} sees the procedure with its photo and the overlay{listed}."
    whose = "" if photo.owner_id == proc.owner_id else f" (it is {photo.owner.username}'s: only they can share it)"
    return (f"{who} sees the procedure, its pictures and 3D models, but not the photo or the overlay: the photo is "
            f"private{whose}. {REDRAWS}")


def previews(user, proc: Procedure) -> dict[str, str]:
    """What others would see after each choice of the page's form, "visibility" or "visibility+photo" (sharing
    the photo too, where ``user`` may) -> the sentence of `viewers_see`, so that the page says it before saving."""
    out = {}
    for visibility in Visibility.values:
        for share in (False, True) if may_share_photo(user, proc) else (False,):
            would = copy.copy(proc)
            would.visibility = visibility
            if share:
                would.photo = copy.copy(proc.photo)
                would.photo.visibility = _shared_as(proc.photo.visibility, visibility)
            out[visibility + ("+photo" if share else "")] = viewers_see(would)
    return out


def set_visibility(user, proc: Procedure, visibility: str, share_photo: bool = False) -> str:
    """Give the procedure ``visibility`` and, with ``share_photo``, its photo at least as much; the sentence of
    `viewers_see`. `Invalid`, naming ``share_photo``, where that photo cannot be shared by ``user``."""
    if share_photo:
        if proc.photo is None:
            raise Invalid("this procedure has no photo to share", "share_photo")
        if proc.photo.owner_id != user.id:
            raise Invalid(f"the photo is {proc.photo.owner.username}'s: only they can share it", "share_photo")
    with transaction.atomic():
        proc.visibility = visibility
        proc.save(update_fields=["visibility", "updated"])
        if share_photo and _shared_as(proc.photo.visibility, visibility) != proc.photo.visibility:
            proc.photo.visibility = _shared_as(proc.photo.visibility, visibility)
            proc.photo.save(update_fields=["visibility"])
    return viewers_see(proc)
