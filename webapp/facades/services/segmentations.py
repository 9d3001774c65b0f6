"""Segmentations of a photo: versions read from the contract's JSON or another tool's file (COCO, LabelMe, CVAT),
the editor's draft, a version written as a file of any of those formats, and proposals for what is not drawn yet.
Bad input raises `Invalid` naming the field; a version there is not is `NotFound`."""

from __future__ import annotations

from django.db import transaction
from django.db.models import Max
from django.utils import timezone

from facaid.completion import RejectedError, explained
from facaid.completion.copies import UnitError, find_copies
from facaid.defaults import DEFAULT_MIN_COPY, DEFAULT_MIN_SCORE
from facaid.formats import interchange
from facaid.photo import appearance
from facaid.segmentation import Segmentation as SegmentationData
from webapp.facades.errors import Invalid, NotFound
from webapp.facades.models import Draft, Photo, Segmentation, check_quota, json_size
from webapp.facades.parsing import parse_segmentation
from webapp.facades.services.files import readable


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
    ``image``, else the only one of ``size``. `Invalid` names the field."""
    if format not in (None, *interchange.FORMATS):
        raise Invalid(f"give one of {', '.join(interchange.FORMATS)}, got {format!r}", "format")
    if format in (None, "segmentation") and not _foreign(data):
        return interchange.Loaded(parse_segmentation(data), "segmentation", None, ())
    try:
        return interchange.load(data, format, image=image, size=size)
    except interchange.SeveralImages as exc:
        raise Invalid(f"{exc} by its name or id", "image") from None
    except interchange.InterchangeError as exc:
        raise Invalid(str(exc), "segmentation") from None


def _segmentation_of(photo: Photo, data, format: str | None = None, image: str | None = None) -> interchange.Loaded:
    """The segmentation, validated, of the photo's size (the rectified image's once there is one): the contract's
    JSON, or another tool's file read by `read_annotations`."""
    w, h = photo.working_size()
    loaded = read_annotations(data, format, image, size=(w, h))
    seg = loaded.segmentation
    if (seg.width, seg.height) != (w, h):
        raise Invalid(f"the segmentation is {seg.width}x{seg.height} but the "
                      f"{'rectified ' if photo.rectified else ''}photo is {w}x{h}", "segmentation")
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
    type and bytes; `NotFound` when there is none."""
    if format not in interchange.FORMATS:
        raise Invalid(f"give one of {', '.join(interchange.FORMATS)}, got {format!r}", "format")
    versions = photo.segmentations.order_by("-version")
    if version is not None:
        if not (version.isascii() and version.isdigit()) or len(version) > 9:
            raise Invalid(f"give a version number, got {version[:20]!r}", "version")
        versions = versions.filter(version=int(version))
    row = versions.first()
    if row is None:
        raise NotFound("no such segmentation version" if version else "this photo has no segmentation yet")
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
        raise Invalid("give a list of rectangles", "rejected")
    if isinstance(min_score, bool) or not isinstance(min_score, int | float) or not 0 <= min_score <= 1:
        raise Invalid(f"give a number in [0, 1], got {min_score!r}", "min_score")
    if not isinstance(use_photo, bool):
        raise Invalid(f"give true or false, got {use_photo!r}", "use_photo")
    if unit is not None and not use_photo:
        raise Invalid("the copies of a unit are found in the photo: leave use_photo true", "unit")
    levels = None
    if use_photo:
        with readable(photo.working_image()) as f:  # grey levels at a bounded scale, the file let go
            levels = appearance.levels(f, seg.width, seg.height)
    try:
        if unit is not None:
            return {"proposals": find_copies(seg, levels, unit, rejected=rejected, min_score=float(min_score))}
        found = explained(seg, levels, rejected=rejected, min_score=float(min_score))
        return {"proposals": found.proposals, "dimmed": found.dimmed, "tried": found.tried}
    except RejectedError as exc:
        raise Invalid(str(exc), "rejected") from None
    except UnitError as exc:
        raise Invalid(str(exc), "unit") from None
    except ValueError as exc:  # too many rectangles
        raise Invalid(str(exc), "segmentation") from None
