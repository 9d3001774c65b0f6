"""What the API's views share: the XML parsers and the content negotiation of annotation files, paging, and
the stored pictures of a procedure with their ETags."""

from __future__ import annotations

from types import SimpleNamespace

from django.core.files.storage import default_storage
from django.http import FileResponse, Http404, HttpResponse
from drf_spectacular.utils import OpenApiParameter
from rest_framework.exceptions import ValidationError
from rest_framework.negotiation import DefaultContentNegotiation
from rest_framework.parsers import BaseParser

from facaid.formats import interchange
from facaid.grammar.procedure import ProcedureError
from webapp.facades import picture_store, throttling
from webapp.facades.models import (
    Procedure,
    Visibility,
)
from webapp.facades.paging import Pagination


class XMLParser(BaseParser):
    """An XML body (a CVAT file) as its bytes, for `facaid.formats.interchange` to read without DTDs."""

    media_type = "application/xml"

    def parse(self, stream, media_type=None, parser_context=None):
        return stream.read() if stream is not None else b""


class TextXMLParser(XMLParser):
    media_type = "text/xml"


class FileFormatNegotiation(DefaultContentNegotiation):
    """Where ``?format=`` names an annotation file's format (coco, labelme, cvat), it is not DRF's choice of a
    renderer (which would answer 404 to ``?format=coco``): the answer's is chosen by the Accept header alone."""

    settings = SimpleNamespace(URL_FORMAT_OVERRIDE=None)


def file_format_param(view):
    view.content_negotiation_class = FileFormatNegotiation
    return view


ANNOTATIONS = {"application/json": dict, "application/xml": str}


IMPORT_PARAMETERS = [
    OpenApiParameter("format", str, enum=interchange.FORMATS,
                     description="the body's format (default: found from the content)"),
    OpenApiParameter("image", str, description="of a COCO or CVAT file of several images, the one to read: its "
                                               "file name or id (default: the only one of the photo's size)")]


def page(request, queryset, serializer):
    pager = Pagination()
    page = pager.paginate_queryset(queryset, request)
    return pager.get_paginated_response(serializer(page, many=True, context={"request": request}).data)


def stored_picture(request, proc: Procedure, kind: str) -> HttpResponse:
    """A stored picture of the procedure, with its digest as the ETag (a 304 when the client has it); shared
    caches may keep a public procedure's a minute."""
    etag = f'"{proc.digest}"'
    if proc.digest and etag in request.headers.get("If-None-Match", ""):
        resp = HttpResponse(status=304)
    else:
        try:
            kept, resp = picture_store.stored(proc, kind, draw=False), None
            if kept is not None:
                name, tag, _ = kept
                try:
                    resp = FileResponse(default_storage.open(name, "rb"), content_type="image/png")
                except FileNotFoundError:  # an edit's refresh replaced it a moment ago: drawn as it is now
                    resp = None
            if resp is None:  # to be drawn: a heavy request, which takes a slot or is told to come back
                with throttling.heavy_slot(request) as held:
                    if not held:
                        return throttling.busy(request, "drawing pictures")
                    name, tag, png = picture_store.stored(proc, kind, redraw=True)
                resp = HttpResponse(png, content_type="image/png")
        except ProcedureError as exc:  # stored before a limit it now breaks
            raise ValidationError({"data": f"this procedure cannot be drawn: {exc}"}) from None
        except LookupError:
            raise Http404("no such procedure") from None
        etag = f'"{tag}"'
    return cacheable(resp, etag, proc)


def cacheable(resp: HttpResponse, etag: str, proc: Procedure) -> HttpResponse:
    """A picture of ``proc`` named by ``etag``: revalidated by it; shared caches may keep a public procedure's a
    minute."""
    resp["ETag"] = etag
    resp["Cache-Control"] = "public, max-age=60" if proc.visibility == Visibility.PUBLIC else "private, no-cache"
    return resp

