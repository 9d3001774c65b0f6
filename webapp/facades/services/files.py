"""The stored files the services read: a field's file open for reading, a file that no longer decodes a 400 naming
``image``, and the bytes a stored file takes."""

from __future__ import annotations

from contextlib import contextmanager

from PIL import Image
from rest_framework.exceptions import ValidationError


@contextmanager
def readable(field):
    """The stored image file, open; a file that no longer decodes while it is read is a 400 naming ``image``."""
    try:
        with field.open("rb") as f:
            yield f
    except (OSError, ValueError, Image.DecompressionBombError) as exc:
        raise ValidationError({"image": f"the photo cannot be read: {exc}"}) from None


def file_size(field) -> int:
    """Bytes a stored file takes; 0 for none, or one gone from storage."""
    try:
        return field.size if field else 0
    except OSError:
        return 0
