"""Photos: stored from an upload (normalized, within the owner's quota), deleted with their files, rectified from
four corners, and their facade's corners proposed. Bad input raises `Invalid` naming the field (a refused
upload: `UploadError`, naming ``image``)."""

from __future__ import annotations

import io

from django.conf import settings
from django.core.files.base import ContentFile

from facaid.photo.corners import propose_corners_file
from facaid.photo.rectify import rectify_file
from webapp.facades import access
from webapp.facades.errors import Invalid
from webapp.facades.models import Photo, Visibility, check_quota
from webapp.facades.services.files import file_size, readable
from webapp.facades.services.segmentations import drop_draft
from webapp.facades.uploads import normalize_photo


def create_photo(owner, upload, title: str = "", visibility: str = Visibility.PRIVATE) -> Photo:
    access.refuse_demo_account(owner, "upload photos")  # they would be the demo's, which nobody changes
    content, _, _ = normalize_photo(upload)  # or `UploadError`, naming ``image``
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


def rectify_photo(photo: Photo, corners) -> Photo:
    """Rectify the photo from four corners (top-left, top-right, bottom-right, bottom-left, in the original's
    pixels) and store the result; the draft, drawn on the image before, goes. `Invalid` names
    ``corners`` for corners far outside the photo or that make no facade."""
    for x, y in corners:
        if not (-photo.width <= x <= 2 * photo.width and -photo.height <= y <= 2 * photo.height):
            raise Invalid(f"corner ({x}, {y}) lies far outside the {photo.width}x{photo.height} photo", "corners")
    with photo.image.open("rb") as f:
        try:
            out = rectify_file(f, corners, max_pixels=settings.FACAID_MAX_RECTIFIED_PIXELS)
        except ValueError as exc:
            raise Invalid(str(exc), "corners") from None
    buf = io.BytesIO()
    out.save(buf, "JPEG", quality=95)  # a 16 MP photo: 0.07 s and 6.5 MB; PNG took 3.4 s and 16 MB
    check_quota(photo.owner_id, buf.tell(), replaced=file_size(photo.rectified))
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
    with readable(photo.image) as f:
        return propose_corners_file(f)
