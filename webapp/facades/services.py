"""What the site does, for the API's views and the pages alike: photos stored from uploads, segmentation
versions, reconstruction jobs (with their per-user cap), procedures forked (their versions: `versions`). Bad input
raises DRF's `ValidationError` naming the field; the callers turn it into a 400 or a message on the page."""

from __future__ import annotations

import hashlib
import io
from collections.abc import Callable
from contextlib import contextmanager
from typing import Any

from django.conf import settings
from django.contrib.auth import get_user_model
from django.core.cache import caches
from django.core.files.base import ContentFile
from django.db import transaction
from django.db.models import Count, Max, Q
from django.http import Http404
from django.utils import timezone
from PIL import Image
from rest_framework.exceptions import APIException, ValidationError

from facaid.completion import RejectedError, explained
from facaid.completion.copies import UnitError, find_copies
from facaid.defaults import DEFAULT_K, DEFAULT_MIN_COPY, DEFAULT_MIN_SCORE
from facaid.formats import interchange
from facaid.photo import appearance
from facaid.photo.corners import propose_corners_file
from facaid.photo.rectify import rectify_file
from facaid.segmentation import Segmentation as SegmentationData
from webapp.facades import access, jobs
from webapp.facades.models import (
    Change,
    Draft,
    Job,
    Photo,
    Procedure,
    ProcedureVersion,
    Segmentation,
    Visibility,
    check_quota,
    json_size,
)
from webapp.facades.parsing import parse_segmentation
from webapp.facades.uploads import UploadError, normalize_photo


def create_photo(owner, upload, title: str = "", visibility: str = Visibility.PRIVATE) -> Photo:
    access.refuse_demo_account(owner, "upload photos")  # they would be the demo's, which nobody changes
    try:
        content, _, _ = normalize_photo(upload)
    except UploadError as exc:
        raise ValidationError({"image": str(exc)}) from None
    check_quota(owner.pk, content.size)
    photo = Photo(owner=owner, title=title, visibility=visibility)
    photo.image.save(content.name, content, save=False)
    photo.stored_bytes = photo.file_bytes()
    photo.save()
    return photo


def delete_photo(photo: Photo) -> None:
    """The photo, its files and its segmentations gone."""
    photo.image.delete(save=False)
    if photo.rectified:
        photo.rectified.delete(save=False)
    photo.delete()


def _file_size(field) -> int:
    """Bytes a stored file takes; 0 for none, or one gone from storage."""
    try:
        return field.size if field else 0
    except OSError:
        return 0


def rectify_photo(photo: Photo, corners) -> Photo:
    """Rectify the photo from four corners (top-left, top-right, bottom-right, bottom-left, in the original's
    pixels) and store the result; the draft, drawn on the image before, goes. A `ValidationError` names
    ``corners`` for corners far outside the photo or that make no facade."""
    for x, y in corners:
        if not (-photo.width <= x <= 2 * photo.width and -photo.height <= y <= 2 * photo.height):
            raise ValidationError({"corners": f"corner ({x}, {y}) lies far outside the {photo.width}x"
                                              f"{photo.height} photo"})
    with photo.image.open("rb") as f:
        try:
            out = rectify_file(f, corners, max_pixels=settings.FACAID_MAX_RECTIFIED_PIXELS)
        except ValueError as exc:
            raise ValidationError({"corners": str(exc)}) from None
    buf = io.BytesIO()
    out.save(buf, "JPEG", quality=95)  # a 16 MP photo: 0.07 s and 6.5 MB; PNG took 3.4 s and 16 MB
    check_quota(photo.owner_id, buf.tell(), replaced=_file_size(photo.rectified))
    if photo.rectified:
        photo.rectified.delete(save=False)
    photo.rectified.save("rectified.jpg", ContentFile(buf.getvalue()), save=False)
    photo.corners = corners
    photo.stored_bytes = photo.file_bytes()
    photo.save()
    drop_draft(photo)  # drawn on the image before: it no longer fits
    return photo


def propose_corners(photo: Photo) -> dict:
    """The facade's four corners proposed from the original photo's lines (`facaid.photo.corners.propose_corners`), in
    its pixels, as `rectify` takes them; nothing is stored."""
    with _readable(photo.image) as f:
        return propose_corners_file(f)


@contextmanager
def _readable(field):
    """The stored image file, open; a file that no longer decodes while it is read is a 400 naming ``image``."""
    try:
        with field.open("rb") as f:
            yield f
    except (OSError, ValueError, Image.DecompressionBombError) as exc:
        raise ValidationError({"image": f"the photo cannot be read: {exc}"}) from None


def _foreign(data) -> bool:
    """Is ``data`` another tool's file (COCO, LabelMe, CVAT) rather than the segmentation contract's JSON?"""
    if isinstance(data, bytes | str):  # a file's content: facaid.formats.interchange reads it, or says why not
        return True
    try:
        return interchange.detect(data) != "segmentation"
    except interchange.InterchangeError:  # neither: the contract's parser says what is wrong, as it always has
        return False


def read_annotations(data, format: str | None = None, image: str | None = None,
                     size: tuple[int, int] | None = None) -> interchange.Loaded:
    """A segmentation from the contract's JSON or from a COCO, LabelMe or CVAT file (its text or bytes, or its
    JSON decoded), found from the content or named by ``format``; of a file of several images, the one named
    ``image``, else the only one of ``size``. A `ValidationError` names the field."""
    if format not in (None, *interchange.FORMATS):
        raise ValidationError({"format": f"give one of {', '.join(interchange.FORMATS)}, got {format!r}"})
    if format in (None, "segmentation") and not _foreign(data):
        return interchange.Loaded(parse_segmentation(data), "segmentation", None, ())
    try:
        return interchange.load(data, format, image=image, size=size)
    except interchange.SeveralImages as exc:
        raise ValidationError({"image": f"{exc} by its name or id"}) from None
    except interchange.InterchangeError as exc:
        raise ValidationError({"segmentation": str(exc)}) from None


def _segmentation_of(photo: Photo, data, format: str | None = None, image: str | None = None) -> interchange.Loaded:
    """The segmentation, validated, of the photo's size (the rectified image's once there is one): the contract's
    JSON, or another tool's file read by `read_annotations`."""
    w, h = photo.working_size()
    loaded = read_annotations(data, format, image, size=(w, h))
    seg = loaded.segmentation
    if (seg.width, seg.height) != (w, h):
        raise ValidationError({"segmentation": f"the segmentation is {seg.width}x{seg.height} but the "
                                               f"{'rectified ' if photo.rectified else ''}photo is {w}x{h}"})
    return loaded


def add_segmentation(photo: Photo, data, format: str | None = None,
                     image: str | None = None) -> tuple[Segmentation, tuple[str, ...]]:
    """A new version from the body of an upload (see `_segmentation_of`), and the warnings of reading it."""
    loaded = _segmentation_of(photo, data, format, image)
    seg = loaded.segmentation
    data = seg.to_dict()
    size = json_size(data)
    with transaction.atomic():
        last = Segmentation.objects.select_for_update().filter(photo=photo).aggregate(v=Max("version"))["v"]
        draft = Draft.objects.filter(photo=photo).values_list("size", flat=True).first() or 0
        check_quota(photo.owner_id, size, replaced=draft)
        version = Segmentation.objects.create(photo=photo, version=(last or 0) + 1, data=data,
                                              rect_count=len(seg.rects), size=size)
        drop_draft(photo)  # saved: the draft it was is the version now
    return version, loaded.warnings


def draft_of(photo: Photo) -> Draft | None:
    return Draft.objects.filter(photo=photo).first()


def drop_draft(photo: Photo) -> None:
    Draft.objects.filter(photo=photo).delete()


def save_draft(photo: Photo, data) -> Draft:
    """Keep (replace) the photo's draft: the segmentation contract's JSON of the photo's size (the rectified
    image's once there is one), validated as a version would be."""
    seg = _segmentation_of(photo, data).segmentation
    data = seg.to_dict()
    size = json_size(data)
    with transaction.atomic():
        kept = Draft.objects.select_for_update().filter(photo=photo).values_list("size", flat=True).first() or 0
        check_quota(photo.owner_id, size, replaced=kept)
        draft, _ = Draft.objects.update_or_create(photo=photo, defaults={
            "data": data, "rect_count": len(seg.rects), "size": size, "updated": timezone.now()})
    return draft


def segmentation_file(photo: Photo, format: str, version: str | None = None) -> tuple[str, str, bytes]:
    """A version of the photo's segmentation (the latest by default) as a file of ``format``: its name, content
    type and bytes; `Http404` when there is none."""
    if format not in interchange.FORMATS:
        raise ValidationError({"format": f"give one of {', '.join(interchange.FORMATS)}, got {format!r}"})
    versions = photo.segmentations.order_by("-version")
    if version is not None:
        if not (version.isascii() and version.isdigit()) or len(version) > 9:
            raise ValidationError({"version": f"give a version number, got {version[:20]!r}"})
        versions = versions.filter(version=int(version))
    row = versions.first()
    if row is None:
        raise Http404("no such segmentation version" if version else "this photo has no segmentation yet")
    seg = SegmentationData.from_dict(row.data)
    # the picture it was drawn on: one drawn before rectification has the original's size
    rectified = bool(photo.rectified) and (seg.width, seg.height) != (photo.width, photo.height)
    name = f"facaid-photo-{str(photo.code)[:8]}-v{row.version}{interchange.SUFFIXES[format]}"
    return name, interchange.CONTENT_TYPES[format], interchange.write(seg, format, image=photo.file_name(rectified))


def complete_segmentation(photo: Photo, data) -> dict:
    """Proposals for what is not drawn yet (`facaid.completion.explained`) in a segmentation of the photo:
    ``{"proposals", "dimmed", "tried"}`` (the places the photo does not confirm, shown for the person to take, and in
    words what was tried where nothing is proposed). The body is the segmentation JSON, optionally with
    ``rejected`` (rectangles not to propose again), ``min_score`` and ``use_photo`` (default true: the photo the
    segmentation is drawn on confirms or rejects each proposal). With ``unit`` (indices of its rectangles: a window
    and what is drawn around it), the copies of that unit the photo shows instead
    (`facaid.completion.copies.find_copies`: ``{"proposals"}``)."""
    seg = _segmentation_of(photo, data, "segmentation").segmentation
    rejected = data.get("rejected") or []
    unit = data.get("unit")
    min_score = data.get("min_score", DEFAULT_MIN_SCORE if unit is None else DEFAULT_MIN_COPY)
    use_photo = data.get("use_photo", True)
    if not isinstance(rejected, list):
        raise ValidationError({"rejected": "give a list of rectangles"})
    if isinstance(min_score, bool) or not isinstance(min_score, int | float) or not 0 <= min_score <= 1:
        raise ValidationError({"min_score": f"give a number in [0, 1], got {min_score!r}"})
    if not isinstance(use_photo, bool):
        raise ValidationError({"use_photo": f"give true or false, got {use_photo!r}"})
    if unit is not None and not use_photo:
        raise ValidationError({"unit": "the copies of a unit are found in the photo: leave use_photo true"})
    levels = None
    if use_photo:
        with _readable(photo.working_image()) as f:  # grey levels at a bounded scale, the file let go
            levels = appearance.levels(f, seg.width, seg.height)
    try:
        if unit is not None:
            return {"proposals": find_copies(seg, levels, unit, rejected=rejected, min_score=float(min_score))}
        found = explained(seg, levels, rejected=rejected, min_score=float(min_score))
        return {"proposals": found.proposals, "dimmed": found.dimmed, "tried": found.tried}
    except RejectedError as exc:
        raise ValidationError({"rejected": str(exc)}) from None
    except UnitError as exc:
        raise ValidationError({"unit": str(exc)}) from None
    except ValueError as exc:  # too many rectangles
        raise ValidationError({"segmentation": str(exc)}) from None


QUOTA_ROOM = 64 * 1024  # bytes of versions a job's result needs at most, about (two versions of a large tree)


class TooManyJobs(APIException):
    status_code = 429
    default_code = "too_many_jobs"


def submit_job(user, segmentation: Segmentation, k=DEFAULT_K, seed=0, prefix: Procedure | None = None,
               prefix_nodes: int = 0, structure: str = "editable") -> Job:
    """Queue a reconstruction; `TooManyJobs` (429) when the user already has FACAID_MAX_ACTIVE_JOBS waiting or
    running, so that one account cannot fill the workers' queue. A re-run from a prefix continues the prefix
    procedure's current version; of the user's own procedure against its own segmentation, its result is that
    procedure's next version, else a new procedure whose parent it is. ``structure``: which of a real facade's two
    procedures is current (`facaid.pipeline.reconstruct`); the other is its first version."""
    params = {"k": k, "seed": seed, "structure": structure}
    if prefix is not None and prefix_nodes > 0:
        current = prefix.current_version()
        params.update(prefix_procedure=str(prefix.code), prefix_nodes=prefix_nodes, parent_id=prefix.id,
                      prefix_version=current.version if current else None,
                      as_version=prefix.owner_id == user.id and prefix.segmentation_id == segmentation.id)
    with transaction.atomic():  # the count and the new row together: two submissions at once cannot both pass
        get_user_model().objects.select_for_update().filter(pk=user.pk).first()
        active = Job.objects.filter(owner=user, status__in=(Job.Status.QUEUED, Job.Status.RUNNING)).count()
        if active >= settings.FACAID_MAX_ACTIVE_JOBS:
            raise TooManyJobs(f"You have {active} reconstructions waiting or running (at most "
                              f"{settings.FACAID_MAX_ACTIVE_JOBS}); submit more when one has finished.")
        check_quota(user.pk, QUOTA_ROOM)  # a full quota refuses the job now, not its result after the work
        return jobs.submit(owner=user, segmentation=segmentation, params=params)


def create_procedure(user, fields: dict) -> Procedure:
    """A procedure of ``user``'s from a validated procedure JSON (``data``) with its title and visibility."""
    if "data" not in fields:
        raise ValidationError({"data": "a procedure JSON is required"})
    return Procedure.objects.create(owner=user, **fields)


GALLERY_CACHE_SECONDS = 60  # how long an unchanged gallery page stays in a process's memory (the most a title edit
# committed out of order with another change could show late)


def gallery_page(where: tuple, build: Callable[[], Any]) -> Any:
    """The public gallery's page at ``where`` (the request's scheme, host and full path: the page's links are made
    from it), from each process's memory while no procedure has changed, else ``build()``'s. The key holds the time
    of the latest change and the counts, one aggregate query, so a procedure made private leaves the listing at
    once (the cache of pages holds at most 500 of them)."""
    changed = Procedure.objects.aggregate(at=Max("updated"), n=Count("id"),
                                          public=Count("id", filter=Q(visibility=Visibility.PUBLIC)))
    state = (changed["at"], changed["n"], changed["public"], *where)
    key = "gallery:" + hashlib.sha256(repr(state).encode()).hexdigest()
    pages = caches["pages"]
    page = pages.get(key)
    if page is None:
        page = build()
        pages.set(key, page, GALLERY_CACHE_SECONDS)
    return page


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
    first), for its owner ``user``; a `ValidationError` naming ``procedure`` without a segmentation ``user`` may see
    (none, or a fork's photo made private since the fork)."""
    if proc.segmentation_id is None:
        raise ValidationError({"procedure": "this procedure has no segmentation to re-run against"})
    if not access.segmentation_visible_to(user, proc):
        raise ValidationError({"procedure": "the photo this procedure was made from is not shared with you, "
                                            "so it cannot be re-run"})
    return submit_job(user, proc.segmentation, k=k, seed=0, prefix=proc, prefix_nodes=nodes)
