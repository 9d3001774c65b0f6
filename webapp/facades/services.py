"""What the site does, for the API's views and the pages alike: photos stored from uploads, segmentation
versions, reconstruction jobs (with their per-user cap), procedures re-measured and forked. Bad input raises DRF's
`ValidationError` naming the field; the callers turn it into a 400 or a message on the page."""

from __future__ import annotations

from django.conf import settings
from django.contrib.auth import get_user_model
from django.db import transaction
from django.db.models import Max
from rest_framework.exceptions import APIException, ValidationError

from facaid.completion import RejectedError, complete
from facaid.defaults import DEFAULT_K, DEFAULT_MIN_SCORE
from webapp.facades import jobs
from webapp.facades.models import Job, Photo, Procedure, Segmentation, Visibility
from webapp.facades.serializers import parse_procedure, parse_segmentation
from webapp.facades.uploads import UploadError, normalize_photo


def create_photo(owner, upload, title: str = "", visibility: str = Visibility.PRIVATE) -> Photo:
    try:
        content, _, _ = normalize_photo(upload)
    except UploadError as exc:
        raise ValidationError({"image": str(exc)}) from None
    photo = Photo(owner=owner, title=title, visibility=visibility)
    photo.image.save(content.name, content, save=False)
    photo.save()
    return photo


def _segmentation_of(photo: Photo, data):
    """The segmentation JSON, validated, of the photo's size (the rectified image's once there is one)."""
    seg = parse_segmentation(data)
    w, h = (photo.rectified.width, photo.rectified.height) if photo.rectified else (photo.width, photo.height)
    if (seg.width, seg.height) != (w, h):
        raise ValidationError({"segmentation": f"the segmentation is {seg.width}x{seg.height} but the "
                                               f"{'rectified ' if photo.rectified else ''}photo is {w}x{h}"})
    return seg


def add_segmentation(photo: Photo, data) -> Segmentation:
    seg = _segmentation_of(photo, data)
    with transaction.atomic():
        last = Segmentation.objects.select_for_update().filter(photo=photo).aggregate(v=Max("version"))["v"]
        return Segmentation.objects.create(photo=photo, version=(last or 0) + 1, data=seg.to_dict(),
                                           rect_count=len(seg.rects))


def complete_segmentation(photo: Photo, data) -> list[dict]:
    """Proposals for what is not drawn yet (`facaid.complete`) in a segmentation of the photo: the body is the
    segmentation JSON, optionally with ``rejected`` (rectangles not to propose again) and ``min_score``."""
    seg = _segmentation_of(photo, data)
    rejected = data.get("rejected") or []
    min_score = data.get("min_score", DEFAULT_MIN_SCORE)
    if not isinstance(rejected, list):
        raise ValidationError({"rejected": "give a list of rectangles"})
    if isinstance(min_score, bool) or not isinstance(min_score, int | float) or not 0 <= min_score <= 1:
        raise ValidationError({"min_score": f"give a number in [0, 1], got {min_score!r}"})
    try:
        return complete(seg, rejected=rejected, min_score=float(min_score))
    except RejectedError as exc:
        raise ValidationError({"rejected": str(exc)}) from None
    except ValueError as exc:  # too many rectangles
        raise ValidationError({"segmentation": str(exc)}) from None


class TooManyJobs(APIException):
    status_code = 429
    default_code = "too_many_jobs"


def submit_job(user, segmentation: Segmentation, k=DEFAULT_K, seed=0, prefix: Procedure | None = None,
               prefix_nodes: int = 0) -> Job:
    """Queue a reconstruction; `TooManyJobs` (429) when the user already has FACAID_MAX_ACTIVE_JOBS waiting or
    running, so that one account cannot fill the workers' queue."""
    params = {"k": k, "seed": seed}
    if prefix is not None and prefix_nodes > 0:
        params.update(prefix_procedure=str(prefix.code), prefix_nodes=prefix_nodes, parent_id=prefix.id)
    with transaction.atomic():  # the count and the new row together: two submissions at once cannot both pass
        get_user_model().objects.select_for_update().filter(pk=user.pk).first()
        active = Job.objects.filter(owner=user, status__in=(Job.Status.QUEUED, Job.Status.RUNNING)).count()
        if active >= settings.FACAID_MAX_ACTIVE_JOBS:
            raise TooManyJobs(f"You have {active} reconstructions waiting or running (at most "
                              f"{settings.FACAID_MAX_ACTIVE_JOBS}); submit more when one has finished.")
        return jobs.submit(owner=user, segmentation=segmentation, params=params)


def remeasure(proc: Procedure) -> None:
    """Pixel accuracy of an edited procedure against the segmentation it was made from."""
    if proc.segmentation_id is None:
        proc.accuracy = None
        return
    from facaid.metrics import procedure_accuracy
    from facaid.segmentation import Segmentation as SegmentationData
    from facaid.segmentation import flatten

    target = flatten(SegmentationData.from_dict(proc.segmentation.data))
    tree = parse_procedure(proc.data)
    if (round(tree.width), round(tree.height)) == (target.width, target.height):
        proc.accuracy = procedure_accuracy(tree, target)
    else:
        proc.accuracy = None  # resized: no longer comparable


def fork_procedure(user, proc: Procedure) -> Procedure:
    """A private copy owned by ``user`` with ``proc`` as its parent; the photo link is kept for its owner only."""
    title = proc.title if proc.title.startswith("Fork of") else f"Fork of {proc.title or 'procedure'}"
    mine = proc.photo is not None and proc.photo.owner == user
    return Procedure.objects.create(
        owner=user, title=title[:200], data=proc.data, parent=proc, accuracy=proc.accuracy, metrics=proc.metrics,
        photo=proc.photo if mine else None, segmentation=proc.segmentation if mine else None)
