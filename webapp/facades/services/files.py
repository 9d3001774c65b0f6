"""The stored files the services read: a field's file open for reading (one that no longer decodes is `Invalid`,
naming ``image``), and the bytes a stored file takes."""

from __future__ import annotations

from contextlib import contextmanager

from PIL import Image

from webapp.facades.errors import Invalid


@contextmanager
def readable(field):
    """The stored image file, open; a file that no longer decodes while it is read is `Invalid`, naming ``image``."""
    try:
        with field.open("rb") as f:
            yield f
    except (OSError, ValueError, Image.DecompressionBombError) as exc:
        raise Invalid(f"the photo cannot be read: {exc}", "image") from None


def file_size(field) -> int:
    """Bytes a stored file takes; 0 for none, or one gone from storage."""
    try:
        return field.size if field else 0
    except OSError:
        return 0
