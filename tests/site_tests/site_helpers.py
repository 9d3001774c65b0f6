"""Helpers of the site tests."""

from __future__ import annotations

import io

from PIL import Image
from rest_framework.test import APIClient

from facaid.generator import generate
from facaid.render import render_segmentation


def client_for(user=None) -> APIClient:
    client = APIClient()
    if user is not None:
        client.force_login(user)  # a session: both the pages and the API see the user
    return client


def image_bytes(fmt: str = "PNG", size=(64, 48), color=(120, 130, 140), **save) -> bytes:
    out = io.BytesIO()
    Image.new("RGB", size, color).save(out, fmt, **save)
    return out.getvalue()


def facade_png(seed: int = 3) -> tuple[bytes, dict]:
    """A 'photo' of a generated facade (its label map in the palette) and its segmentation JSON."""
    sample = generate(seed)
    out = io.BytesIO()
    render_segmentation(sample.segmentation).save(out, "PNG")
    return out.getvalue(), sample.segmentation.to_dict()


def upload(client, data: bytes, name: str = "photo.png", **fields):
    from django.core.files.uploadedfile import SimpleUploadedFile

    return client.post("/api/v1/photos/", {"image": SimpleUploadedFile(name, data), **fields}, format="multipart")
