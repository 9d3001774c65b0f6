"""Who may see and change what. Objects someone may not see are `NotFound` (a 404: their existence is not
revealed); objects they may see but not change are `NotAllowed` (a 403)."""

from __future__ import annotations

from django.core.exceptions import ValidationError
from django.db.models import Q, QuerySet

from webapp.facades.errors import NotAllowed, NotFound, NotSignedIn
from webapp.facades.models import Job, Photo, Procedure, Segmentation, Visibility

READABLE = (Visibility.PUBLIC, Visibility.UNLISTED)  # by link; only public ones are listed
# large JSON columns that lists and job statuses never show: not read at all (they were most of a gallery page's time)
LISTED_WITHOUT = ("data", "metrics", "parent__data", "parent__metrics")
JOB_WITHOUT = ("segmentation__data", "result__data", "result__metrics")
# the demo account (`manage.py demo`): its password is public, so what the front page shows of it is read-only
DEMO_USERNAME = "demo"
DEMO_READ_ONLY = ("the demo cannot be changed, by the demo account either (its password is public and the front "
                  "page shows it): fork the procedure to edit a copy of your own")


def _readable(qs: QuerySet, user, owner_field: str = "owner", visibility_field: str = "visibility") -> QuerySet:
    q = Q(**{f"{visibility_field}__in": READABLE})
    if user.is_authenticated:
        q |= Q(**{owner_field: user})
    return qs.filter(q)


def _get(qs: QuerySet, code):
    try:
        return qs.get(code=code)
    except (qs.model.DoesNotExist, ValidationError, ValueError, TypeError):  # a malformed UUID: not found
        raise NotFound(f"no such {qs.model._meta.verbose_name}") from None


def _owned(obj, user, owner):
    if not user.is_authenticated:
        raise NotSignedIn("sign in to change this")
    if owner != user:
        raise NotAllowed("only the owner may change this")
    if is_demo(obj):
        raise NotAllowed(DEMO_READ_ONLY)
    return obj


def is_demo(obj: Photo | Procedure) -> bool:
    """Is ``obj`` the demo's: a photo of the demo account's, or a procedure of its with no parent (what the worker
    made of its photo)? Nobody changes those, the demo account included; its forks and saved copies are its own."""
    if isinstance(obj, Procedure) and obj.parent_id is not None:
        return False
    return obj.owner.username == DEMO_USERNAME


def refuse_demo_account(user, what: str) -> None:
    """`NotAllowed` (a 403) for the demo account (anyone may log in as it), which may not make ``what``."""
    if user.is_authenticated and user.get_username() == DEMO_USERNAME:
        raise NotAllowed(f"the demo account cannot {what} (its password is public): sign up to do it as "
                               "yourself, or fork the demo procedure to edit a copy")


def get_photo_for_user(user, code) -> Photo:
    return _get(_readable(Photo.objects.all(), user), code)


def get_rw_photo_for_user(user, code) -> Photo:
    photo = get_photo_for_user(user, code)
    return _owned(photo, user, photo.owner)


def photo_visible_to(user, photo: Photo | None) -> bool:
    """May ``user`` see this photo (for example under a procedure made from it)?"""
    return photo is not None and ((user.is_authenticated and photo.owner_id == user.id)
                                  or photo.visibility in READABLE)


def _owns(user, obj) -> bool:
    return user.is_authenticated and obj.owner_id == user.id


def parent_named_to(user, child: Procedure, parent: Procedure | None) -> bool:
    """May ``child``'s page or JSON name ``parent`` to ``user``? A public parent, or one of the user's own; an
    unlisted one only to the owner of the fork (who had its link), as naming it publishes the link."""
    if parent is None:
        return False
    if parent.visibility == Visibility.PUBLIC or _owns(user, parent):
        return True
    return parent.visibility == Visibility.UNLISTED and _owns(user, child)


def visible_lineage(user, proc: Procedure) -> list[Procedure]:
    """The procedure's ancestors, nearest first, up to the first one ``user`` may not be shown."""
    out, child = [], proc
    for ancestor in proc.lineage():
        if not parent_named_to(user, child, ancestor):
            break
        out.append(ancestor)
        child = ancestor
    return out


def get_segmentation_for_user(user, code) -> Segmentation:
    qs = _readable(Segmentation.objects.select_related("photo"), user, "photo__owner", "photo__visibility")
    return _get(qs, code)


def segmentation_visible_to(user, proc: Procedure) -> bool:
    """May ``user`` see the segmentation ``proc`` was made from, and so re-run it? The rule of
    `get_segmentation_for_user`: its photo is theirs, public or unlisted (a fork's may have been made private since)."""
    return proc.segmentation_id is not None and _readable(
        Segmentation.objects.filter(pk=proc.segmentation_id), user, "photo__owner", "photo__visibility").exists()


def get_procedure_for_user(user, code) -> Procedure:
    return _get(_readable(Procedure.objects.select_related("owner", "parent", "photo"), user), code)


def get_procedure_picture_for_user(user, code) -> Procedure:
    """The procedure as its pictures need it: the tree is read only if a picture has to be drawn."""
    return _get(_readable(Procedure.objects.defer("data", "metrics"), user), code)


def get_rw_procedure_for_user(user, code) -> Procedure:
    proc = get_procedure_for_user(user, code)
    return _owned(proc, user, proc.owner)


def get_job_for_user(user, code) -> Job:
    if not user.is_authenticated:
        raise NotFound("no such job")
    return _get(Job.objects.filter(owner=user).select_related("result", "segmentation__photo").defer(
        *JOB_WITHOUT), code)


def listed(procedures: QuerySet) -> QuerySet:
    """Procedures as lists show them: with their owner, parent and photo (whether the viewer may see it decides what
    they are shown, `disclosure`), without the JSON columns."""
    return procedures.select_related("owner", "parent", "photo").defer(*LISTED_WITHOUT)


def public_procedures() -> QuerySet:
    return listed(Procedure.objects.filter(visibility=Visibility.PUBLIC))
