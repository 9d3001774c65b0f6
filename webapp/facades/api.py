"""The JSON API (``/api/v1/``): everything the pages do. Documented by the OpenAPI schema at
``/api/v1/schema``. Private objects of others are 404; others' public objects are read-only (403 to change)."""

from __future__ import annotations

import hashlib
import io
from types import SimpleNamespace

from django.conf import settings
from django.core.cache import caches
from django.core.files.base import ContentFile
from django.core.files.storage import default_storage
from django.db import transaction
from django.db.models import Count, Max, OuterRef, Q, Subquery
from django.http import FileResponse, Http404, HttpResponse
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import status
from rest_framework.decorators import (
    api_view,
    authentication_classes,
    parser_classes,
    permission_classes,
    throttle_classes,
)
from rest_framework.exceptions import NotAuthenticated, ValidationError
from rest_framework.negotiation import DefaultContentNegotiation
from rest_framework.parsers import BaseParser, FormParser, MultiPartParser
from rest_framework.permissions import AllowAny, IsAuthenticated
from rest_framework.response import Response

from facaid.formats import interchange
from facaid.formats.relief import MAX_MESH_RECTS, drawn_leaves
from facaid.grammar import to_segmentation
from facaid.grammar.procedure import ProcedureError
from facaid.labels import LABELS
from facaid.parameters import named_parameters, set_parameters
from facaid.photo.rectify import rectify_file
from facaid.variation import vary
from webapp.facades import access, downloads, pictures, rendering, services, sharing, versions
from webapp.facades.downloads import DOWNLOADS
from webapp.facades.jsonbody import JSONParser
from webapp.facades.models import (
    Change,
    Draft,
    Job,
    Photo,
    Procedure,
    ProcedureVersion,
    Segmentation,
    Visibility,
)
from webapp.facades.paging import Pagination
from webapp.facades.serializers import (
    ConvertSerializer,
    JobCreateSerializer,
    JobSerializer,
    ParametersSerializer,
    PhotoSerializer,
    PhotoUploadSerializer,
    ProcedureEditSerializer,
    ProcedureSerializer,
    ProcedureSummarySerializer,
    ProcedureVersionSerializer,
    ProcedureVersionSummarySerializer,
    ProcedureWriteSerializer,
    RectifySerializer,
    RerunSerializer,
    SaveAsNewSerializer,
    SegmentationSerializer,
    SegmentationSummarySerializer,
    VariationsSerializer,
    parse_procedure,
)
from webapp.facades.throttling import HEAVY

GALLERY_CACHE_SECONDS = 60  # how long an unchanged gallery page stays in a process's memory (the most a title edit
# committed out of order with another change could show late)


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


def _page(request, queryset, serializer):
    pager = Pagination()
    page = pager.paginate_queryset(queryset, request)
    return pager.get_paginated_response(serializer(page, many=True, context={"request": request}).data)


# --- photos ----------------------------------------------------------------------------------------------------

@extend_schema(methods=["GET"], responses=PhotoSerializer(many=True), summary="Your photos")
@extend_schema(methods=["POST"], request={"multipart/form-data": PhotoUploadSerializer},
               responses={201: PhotoSerializer}, summary="Upload a photo (JPEG, PNG or WebP)")
@api_view(["GET", "POST"])
@permission_classes([IsAuthenticated])
@parser_classes([MultiPartParser, FormParser])
def photos(request):
    if request.method == "GET":
        latest = Segmentation.objects.filter(photo=OuterRef("pk")).order_by("-version").values("code")[:1]
        photos = Photo.objects.filter(owner=request.user).select_related("owner").annotate(
            latest_segmentation_code=Subquery(latest))
        return _page(request, photos, PhotoSerializer)
    form = PhotoUploadSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    photo = services.create_photo(request.user, form.validated_data["image"], form.validated_data.get("title", ""),
                                  form.validated_data["visibility"])
    return Response(PhotoSerializer(photo).data, status=status.HTTP_201_CREATED)


@extend_schema(methods=["GET"], responses=PhotoSerializer, summary="A photo")
@extend_schema(methods=["PATCH"], request=PhotoSerializer, responses=PhotoSerializer,
               summary="Change a photo's title or visibility")
@extend_schema(methods=["DELETE"], responses={204: None}, summary="Delete a photo with its segmentations")
@api_view(["GET", "PATCH", "DELETE"])
@permission_classes([AllowAny])
def photo_detail(request, code):
    if request.method == "GET":
        return Response(PhotoSerializer(access.get_photo_for_user(request.user, code)).data)
    photo = access.get_rw_photo_for_user(request.user, code)
    if request.method == "DELETE":
        photo.image.delete(save=False)
        if photo.rectified:
            photo.rectified.delete(save=False)
        photo.delete()
        return Response(status=status.HTTP_204_NO_CONTENT)
    form = PhotoSerializer(photo, data=request.data, partial=True)
    form.is_valid(raise_exception=True)
    form.save()
    return Response(form.data)


@extend_schema(parameters=[OpenApiParameter("rectified", bool, description="the rectified image")],
               responses={(200, "image/*"): bytes}, summary="The photo's image file")
@api_view(["GET"])
@permission_classes([AllowAny])
def photo_image(request, code):
    photo = access.get_photo_for_user(request.user, code)
    field = photo.rectified if request.query_params.get("rectified") and photo.rectified else photo.image
    return FileResponse(field.open("rb"))


@extend_schema(request=RectifySerializer, responses=PhotoSerializer,
               summary="Rectify the photo from four corners (a homography); the result is stored")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def photo_rectify(request, code):
    photo = access.get_rw_photo_for_user(request.user, code)
    form = RectifySerializer(data=request.data)
    form.is_valid(raise_exception=True)
    corners = form.validated_data["corners"]
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
    out.save(buf, "PNG")
    if photo.rectified:
        photo.rectified.delete(save=False)
    photo.rectified.save("rectified.png", ContentFile(buf.getvalue()), save=False)
    photo.corners = corners
    photo.save()
    Draft.objects.filter(photo=photo).delete()  # drawn on the image before: it no longer fits
    return Response(PhotoSerializer(photo).data)


@extend_schema(request=None, responses={200: dict},
               summary="Propose the facade's four corners from the photo's lines and vanishing points "
                       "(rectify.propose_corners): {'corners': [[x, y] x 4] (top-left, top-right, bottom-right, "
                       "bottom-left, in the original photo's pixels, as rectify takes them), 'confidence' (0..1: the "
                       "share of the four sides that detected lines cover), 'notes', 'lines'}; nothing is stored")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
def photo_propose_corners(request, code):
    return Response(services.propose_corners(access.get_rw_photo_for_user(request.user, code)))


# --- segmentations ------------------------------------------------------------------------------------------------

@extend_schema(methods=["GET"], responses=SegmentationSummarySerializer(many=True),
               summary="Versions, newest first (without their rectangles: GET segmentations/<code>/ for those)")
@extend_schema(methods=["POST"], request=ANNOTATIONS, parameters=IMPORT_PARAMETERS,
               responses={201: SegmentationSerializer},
               summary="Save a new version: the segmentation JSON contract, or a COCO or LabelMe JSON or CVAT XML "
                       "file (docs/interchange.md); its size must match the photo's; the answer lists 'warnings' "
                       "(polygons read as boxes)")
@api_view(["GET", "POST"])
@permission_classes([AllowAny])
@parser_classes([JSONParser, XMLParser, TextXMLParser])
@file_format_param
def photo_segmentations(request, code):
    if request.method == "GET":
        photo = access.get_photo_for_user(request.user, code)
        return _page(request, photo.segmentations.select_related("photo").defer("data").order_by("-version"),
                     SegmentationSummarySerializer)
    if not request.user.is_authenticated:
        raise NotAuthenticated()
    photo = access.get_rw_photo_for_user(request.user, code)
    seg, warnings = services.add_segmentation(photo, request.data, request.query_params.get("format"),
                                              request.query_params.get("image"))
    return Response({**SegmentationSerializer(seg).data, "warnings": list(warnings)}, status=status.HTTP_201_CREATED)


def _draft(draft) -> dict:
    return {"draft": None if draft is None else {"data": draft.data, "rect_count": draft.rect_count,
                                                 "updated": draft.updated.isoformat()}}


@extend_schema(methods=["GET"], responses={200: dict},
               summary="The owner's unsaved draft of the photo's segmentation: {'draft': {data, rect_count, updated}} "
                       "or {'draft': null}")
@extend_schema(methods=["PUT"], request={"application/json": dict}, responses={200: dict},
               summary="Keep the editor's unsaved segmentation (the contract's JSON, of the photo's size) as the "
                       "photo's draft, replacing the last one; saving a version removes it")
@extend_schema(methods=["DELETE"], responses={204: None}, summary="Drop the photo's draft")
@api_view(["GET", "PUT", "DELETE"])
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def photo_draft(request, code):
    photo = access.get_rw_photo_for_user(request.user, code)  # the owner's: a draft is no one else's business
    if request.method == "PUT":
        return Response(_draft(services.save_draft(photo, request.data)))
    if request.method == "DELETE":
        Draft.objects.filter(photo=photo).delete()
        return Response(status=status.HTTP_204_NO_CONTENT)
    return Response(_draft(Draft.objects.filter(photo=photo).first()))


@extend_schema(parameters=[OpenApiParameter("format", str, enum=interchange.FORMATS,
                                            description="segmentation (our JSON, the default), coco, labelme or "
                                                        "cvat"),
                           OpenApiParameter("version", int, description="the version (default: the latest)")],
               responses={(200, "application/octet-stream"): bytes},
               summary="The photo's segmentation as a file: our JSON, COCO, LabelMe or CVAT for images XML")
@api_view(["GET"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@file_format_param
def photo_segmentation_file(request, code):
    photo = access.get_photo_for_user(request.user, code)
    name, content_type, body = services.segmentation_file(photo, request.query_params.get("format", "segmentation"),
                                                          request.query_params.get("version"))
    resp = HttpResponse(body, content_type=content_type)
    resp["Content-Disposition"] = f'attachment; filename="{name}"'
    return resp


@extend_schema(request={"application/json": dict}, responses={200: dict},
               summary="Propose the elements not drawn yet (facaid.complete): the body is the segmentation drawn so "
                       "far, with optional 'rejected' rectangles and 'min_score'; returns {'proposals': [{label, x0, "
                       "y0, x1, y1, score, reason}]}; nothing is stored")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def photo_complete(request, code):
    photo = access.get_photo_for_user(request.user, code)
    if not isinstance(request.data, dict):
        raise ValidationError({"segmentation": "must be a JSON object"})
    return Response({"proposals": services.complete_segmentation(photo, request.data)})


@extend_schema(responses=SegmentationSerializer, summary="One segmentation version")
@api_view(["GET"])
@permission_classes([AllowAny])
def segmentation_detail(request, code):
    return Response(SegmentationSerializer(access.get_segmentation_for_user(request.user, code)).data)


# --- jobs ---------------------------------------------------------------------------------------------------------

@extend_schema(methods=["GET"], responses=JobSerializer(many=True), summary="Your jobs, newest first")
@extend_schema(methods=["POST"], request=JobCreateSerializer, responses={202: JobSerializer},
               summary="Reconstruct a procedure from a segmentation (optionally continuing a procedure's "
                       "first nodes)")
@api_view(["GET", "POST"])
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def job_list(request):
    if request.method == "GET":
        return _page(request, Job.objects.filter(owner=request.user).select_related("segmentation", "result").defer(
            *access.JOB_WITHOUT), JobSerializer)
    form = JobCreateSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    v = form.validated_data
    seg = access.get_segmentation_for_user(request.user, v["segmentation"])
    if seg.photo.owner != request.user:
        raise ValidationError({"segmentation": "fork the photo's procedure or upload your own photo to "
                                               "reconstruct it"})
    prefix = access.get_procedure_for_user(request.user, v["prefix_procedure"]) if v["prefix_procedure"] else None
    job = services.submit_job(request.user, seg, v["k"], v["seed"], prefix, v["prefix_nodes"], v["structure"])
    return Response(JobSerializer(job).data, status=status.HTTP_202_ACCEPTED)


@extend_schema(responses=JobSerializer, summary="A job's status and progress")
@api_view(["GET"])
@permission_classes([AllowAny])
def job_detail(request, code):
    return Response(JobSerializer(access.get_job_for_user(request.user, code)).data)


# --- procedures ---------------------------------------------------------------------------------------------------

@extend_schema(methods=["GET"], responses=ProcedureSummarySerializer(many=True), summary="Your procedures")
@extend_schema(methods=["POST"], request=ProcedureWriteSerializer, responses={201: ProcedureSerializer},
               summary="Store a procedure JSON (imported or edited)")
@api_view(["GET", "POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def procedure_list(request):
    if request.method == "GET":
        return _page(request, access.listed(Procedure.objects.filter(owner=request.user)), ProcedureSummarySerializer)
    form = ProcedureWriteSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    if "data" not in form.validated_data:
        raise ValidationError({"data": "a procedure JSON is required"})
    proc = Procedure.objects.create(owner=request.user, **form.validated_data)
    return Response(ProcedureSerializer(proc, context={"request": request}).data, status=status.HTTP_201_CREATED)


@extend_schema(responses=ProcedureSummarySerializer(many=True), auth=[],
               summary="Public procedures, newest first (the same for everyone)")
@api_view(["GET"])
@authentication_classes([])  # the listing is the public's: no session or token is read
@permission_classes([AllowAny])
def gallery(request):
    """Served from each process's memory while no procedure has changed: the key holds the time of the latest
    change and the counts, one aggregate query, so a procedure made private leaves the listing at once."""
    changed = Procedure.objects.aggregate(at=Max("updated"), n=Count("id"),
                                          public=Count("id", filter=Q(visibility=Visibility.PUBLIC)))
    # the query as sent: the page's links are made from it (the cache of pages holds at most 500 of them)
    where = (changed["at"], changed["n"], changed["public"], request.scheme, request.get_host(),
             request.get_full_path())
    key = "gallery:" + hashlib.sha256(repr(where).encode()).hexdigest()
    pages = caches["pages"]
    page = pages.get(key)
    if page is None:
        page = _page(request, access.public_procedures(), ProcedureSummarySerializer).data
        pages.set(key, page, GALLERY_CACHE_SECONDS)
    return Response(page)


@extend_schema(methods=["GET"], responses=ProcedureSerializer, summary="A procedure")
@extend_schema(methods=["PATCH"], request=ProcedureEditSerializer, responses=ProcedureSerializer,
               summary="Edit title, visibility or the procedure itself: a changed tree is a new version, re-measured "
                       "(the answer's accuracy and metrics are the new version's)")
@extend_schema(methods=["DELETE"], responses={204: None}, summary="Delete a procedure")
@api_view(["GET", "PATCH", "DELETE"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def procedure_detail(request, code):
    if request.method == "GET":
        return Response(ProcedureSerializer(access.get_procedure_for_user(request.user, code),
                                           context={"request": request}).data)
    proc = access.get_rw_procedure_for_user(request.user, code)
    if request.method == "DELETE":
        proc.delete()
        return Response(status=status.HTTP_204_NO_CONTENT)
    form = ProcedureEditSerializer(data=request.data, partial=True)
    form.is_valid(raise_exception=True)
    changes = dict(form.validated_data)
    tree = changes.pop("data", None)
    visibility, share_photo = changes.pop("visibility", None), changes.pop("share_photo", False)
    with transaction.atomic():  # a photo that cannot be shared leaves the title and the tree as they were
        for key, value in changes.items():
            setattr(proc, key, value)
        if tree is None:
            proc.save()
        else:
            versions.save_tree(proc, tree)
        if visibility is not None or share_photo:
            sharing.set_visibility(request.user, proc, visibility or proc.visibility, share_photo)
    return Response(ProcedureSerializer(proc, context={"request": request}).data)


@extend_schema(request=None, responses={201: ProcedureSerializer},
               summary="Fork: your own private copy, with a link to its parent")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
def procedure_fork(request, code):
    fork = services.fork_procedure(request.user, access.get_procedure_for_user(request.user, code))
    return Response(ProcedureSerializer(fork, context={"request": request}).data, status=status.HTTP_201_CREATED)


@extend_schema(request=VariationsSerializer, responses={200: dict},
               summary="Variants of a procedure (counts, resizes, swaps), deterministic by seed; not stored")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def procedure_variations(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    form = VariationsSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    try:
        ranges = {k: tuple(v) for k, v in form.validated_data.get("ranges", {}).items()} or None
        variants = vary(parse_procedure(proc.data), form.validated_data["n"], form.validated_data["seed"], ranges)
    except (ProcedureError, ValueError) as exc:
        field = "ranges" if form.validated_data.get("ranges") else "data"
        raise ValidationError({field: f"no variations of this procedure: {exc}"}) from None
    return Response({"variants": [v.to_dict() for v in variants]})


def _leaves(tree) -> list | None:
    """Where the tree draws each leaf, for the page's picture-to-tree selection: [label, x0, y0, x1, y1, node path]
    in whole pixels; None past `MAX_MESH_RECTS` rectangles (a real facade draws a few hundred)."""
    rows, paths = drawn_leaves(tree)
    if len(rows) > MAX_MESH_RECTS:
        return None
    return [[LABELS[r[0]], *r[1:], path] for r, path in zip(rows.tolist(), paths, strict=True)]


@extend_schema(methods=["GET"], request=None, responses={200: dict},
               summary="The named parameters (floors, floor height, bays, ...) and where each leaf is drawn: "
                       "{'parameters': [...], 'leaves': [[label, x0, y0, x1, y1, node path], ...]}")
@extend_schema(methods=["POST"], request=ParametersSerializer, responses={200: dict},
               summary="Set named parameters: {'data', 'parameters', 'leaves', 'accuracy', 'metrics', 'version'}; "
                       "with save, the result is the next version (the accuracy is that version's, measured on save)")
@api_view(["GET", "POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def procedure_parameters(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    if request.method == "GET":
        tree = parse_procedure(proc.data)
        return Response({"parameters": [p.to_dict() for p in named_parameters(tree)], "leaves": _leaves(tree)})
    form = ParametersSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    try:
        tree = form.validated_data.get("data") or proc.data
        edited = set_parameters(parse_procedure(tree), form.validated_data["values"])
    except (ProcedureError, ValueError) as exc:
        raise ValidationError({"values": str(exc)}) from None
    answer = {"data": edited.to_dict(), "parameters": [p.to_dict() for p in named_parameters(edited)],
              "leaves": _leaves(edited), "accuracy": None, "metrics": None, "version": None}
    if form.validated_data["save"]:
        proc = access.get_rw_procedure_for_user(request.user, code)
        names = ", ".join(f"{k} {v:g}" for k, v in form.validated_data["values"].items())
        versions.save_tree(proc, answer["data"], Change(ProcedureVersion.Kind.EDIT, f"set {names}"[:200]))
        answer.update(accuracy=proc.accuracy, metrics=proc.metrics, version=proc.current_version().version)
    return Response(answer)


@extend_schema(request=ConvertSerializer, responses={200: dict},
               summary="Read a COCO, LabelMe or CVAT file (or our segmentation JSON) into the segmentation JSON "
                       "contract: {'segmentation', 'format', 'image', 'warnings'}; nothing is stored")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def convert(request):
    form = ConvertSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    v = form.validated_data
    size = (v["width"], v["height"]) if "width" in v and "height" in v else None
    try:
        loaded = services.read_annotations(v["text"], v.get("format"), v.get("image"), size)
    except ValidationError as exc:  # the file is the request's 'text'
        detail = exc.detail
        raise ValidationError({"text" if k == "segmentation" else k: m for k, m in detail.items()}) from None
    return Response({"segmentation": loaded.segmentation.to_dict(), "format": loaded.format, "image": loaded.image,
                     "warnings": list(loaded.warnings)})


@extend_schema(request={"application/json": dict}, responses={(200, "image/png"): bytes},
               summary="Render a procedure JSON (the live preview of edited parameters)")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def render_preview(request):
    seg = to_segmentation(parse_procedure(request.data))
    return HttpResponse(rendering.label_map_png(seg, 1024), content_type="image/png")


@extend_schema(parameters=[OpenApiParameter("alpha", float, description="overlay opacity, 0..1"),
                           OpenApiParameter("metres_per_pixel", float,
                                            description="the scale of procedure.cga, mesh.zip and the 3D models "
                                                        "(default: the photo's real size, else a storey is 3 m)")],
               responses={(200, "application/octet-stream"): bytes},
               summary="Downloads: procedure.json, segmentation.json (executed; segmentation.coco.json, "
                       "segmentation.labelme.json and segmentation.cvat.xml the same as another tool's annotations of "
                       "labels.png), labels.png, labels.svg (one group "
                       "of rectangles per class), procedure.cga (CityEngine CGA rules), mesh.zip (a relief mesh: "
                       "facade.obj and facade.mtl), facade.glb and facade.gltf (glTF), facade-photo.glb (with the "
                       "photo), facade.ifc (IFC4), facade.city.json (CityJSON 2.0), overlay.png")
@api_view(["GET"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
def procedure_download(request, code, name):
    download = DOWNLOADS.get(name)
    if download is None:
        raise Http404(f"no download named {name!r}; there are {', '.join(DOWNLOADS)}")
    if download.build is None:  # kept in storage: served as a file, the tree read only if it must be drawn
        proc = access.get_procedure_picture_for_user(request.user, code)
        resp = _picture(request, proc, name)
    else:
        proc = access.get_procedure_for_user(request.user, code)
        if download.needs_photo and not access.photo_visible_to(request.user, proc.photo):
            raise ValidationError({"photo": f"{name} is drawn with the photo, and this procedure has no photo you "
                                            "may see"})
        resp = HttpResponse(downloads.build(name, proc, request.query_params), content_type=download.content_type)
    resp["Content-Disposition"] = f'attachment; filename="{downloads.stem(proc)}-{name}"'
    return resp


def _picture(request, proc: Procedure, kind: str) -> HttpResponse:
    """A stored picture of the procedure, with its digest as the ETag (a 304 when the client has it); shared
    caches may keep a public procedure's a minute."""
    etag = f'"{proc.digest}"'
    if proc.digest and etag in request.headers.get("If-None-Match", ""):
        resp = HttpResponse(status=304)
    else:
        try:
            name, tag, png = pictures.stored(proc, kind)
            if png is None:
                try:
                    resp = FileResponse(default_storage.open(name, "rb"), content_type="image/png")
                except FileNotFoundError:  # an edit's refresh replaced it a moment ago: drawn as it is now
                    name, tag, png = pictures.stored(proc, kind, redraw=True)
            if png is not None:
                resp = HttpResponse(png, content_type="image/png")
        except ProcedureError as exc:  # stored before a limit it now breaks
            raise ValidationError({"data": f"this procedure cannot be drawn: {exc}"}) from None
        except LookupError:
            raise Http404("no such procedure") from None
        etag = f'"{tag}"'
    return _cacheable(resp, etag, proc)


def _cacheable(resp: HttpResponse, etag: str, proc: Procedure) -> HttpResponse:
    """A picture of ``proc`` named by ``etag``: revalidated by it; shared caches may keep a public procedure's a
    minute."""
    resp["ETag"] = etag
    resp["Cache-Control"] = "public, max-age=60" if proc.visibility == Visibility.PUBLIC else "private, no-cache"
    return resp


@extend_schema(responses={(200, "image/png"): bytes, 304: None},
               summary="The procedure's thumbnail (its label map, at most 320 px a side), as the gallery shows it")
@api_view(["GET"])
@permission_classes([AllowAny])
def procedure_thumbnail(request, code):
    return _picture(request, access.get_procedure_picture_for_user(request.user, code), "thumbnail.png")


@extend_schema(request=RerunSerializer, responses={202: JobSerializer},
               summary="Re-run inference keeping the procedure's first `nodes` nodes (BFS)")
@api_view(["POST"])
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def procedure_rerun(request, code):
    proc = access.get_rw_procedure_for_user(request.user, code)
    form = RerunSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    job = services.rerun(request.user, proc, form.validated_data["nodes"], form.validated_data["k"])
    return Response(JobSerializer(job).data, status=status.HTTP_202_ACCEPTED)


# --- versions -----------------------------------------------------------------------------------------------------

@extend_schema(responses=ProcedureVersionSummarySerializer(many=True),
               summary="The procedure's versions, newest first: every save of its tree, with its pixel accuracy "
                       "against the procedure's segmentation as measured then, what made it (created, edit, revert, "
                       "rerun), the version it was made from and a re-run's warning when it fits worse (their trees: "
                       "versions/<n>/)")
@api_view(["GET"])
@permission_classes([AllowAny])
def procedure_versions(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    pager = Pagination()
    page = pager.paginate_queryset(proc.versions.defer("data").order_by("-version"), request)
    for version in page:
        version.procedure = proc
    return pager.get_paginated_response(ProcedureVersionSummarySerializer(page, many=True).data)


@extend_schema(responses=ProcedureVersionSerializer, summary="One version of the procedure, with its tree")
@api_view(["GET"])
@permission_classes([AllowAny])
def procedure_version(request, code, number):
    proc = access.get_procedure_for_user(request.user, code)
    return Response(ProcedureVersionSerializer(versions.get_version(proc, number)).data)


@extend_schema(responses={(200, "image/png"): bytes, 304: None},
               summary="A version's label map (at most 1,024 px a side), named by its digest (the ETag)")
@api_view(["GET"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
def procedure_version_picture(request, code, number):
    proc = access.get_procedure_for_user(request.user, code)
    version = versions.get_version(proc, number)
    etag = f'"{version.digest}"'
    if etag in request.headers.get("If-None-Match", ""):
        return _cacheable(HttpResponse(status=304), etag, proc)
    seg = to_segmentation(parse_procedure(version.data))
    return _cacheable(HttpResponse(rendering.label_map_png(seg, rendering.COMPARE_SIDE), content_type="image/png"),
                      etag, proc)


@extend_schema(request=None, responses={201: ProcedureSerializer},
               summary="Revert: a new version whose tree is version <n>'s, measured again (nothing is deleted); "
                       "the owner's (others: 403, or 404 where they may not see it); a 400 when it is the current "
                       "tree")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
def procedure_revert(request, code, number):
    proc = access.get_rw_procedure_for_user(request.user, code)
    versions.revert(proc, number)
    return Response(ProcedureSerializer(proc, context={"request": request}).data, status=status.HTTP_201_CREATED)


COMPARED = [OpenApiParameter("a", int, required=True, description="a version number (the older, say)"),
            OpenApiParameter("b", int, required=True, description="another (the newer)")]


@extend_schema(parameters=COMPARED, responses={200: dict},
               summary="Compare two versions: {'a', 'b' (each version as versions/ lists it, with its 'width' and "
                       "'height'), 'differing' (the share of the pictures' pixels whose label differs, on one canvas "
                       "of at most 1,024 px a side), 'differing_pixels', 'pixels', 'overlay' (compare.png: the "
                       "difference picture), 'segmentation' (what both accuracies were measured against)}")
@api_view(["GET"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
def procedure_compare(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    a, b, diff = versions.compare(proc, request.query_params.get("a"), request.query_params.get("b"))
    sides = {}
    for key, version in (("a", a), ("b", b)):
        tree = parse_procedure(version.data)
        sides[key] = {**ProcedureVersionSummarySerializer(version).data, "width": tree.width, "height": tree.height}
    seg = ProcedureSerializer(proc, context={"request": request}).get_segmentation(proc)
    return Response({**sides, "differing": diff["differing"] / diff["pixels"], "differing_pixels": diff["differing"],
                     "pixels": diff["pixels"], "segmentation": seg,
                     "overlay": f"/api/v1/procedures/{proc.code}/versions/compare.png?a={a.version}&b={b.version}"})


@extend_schema(parameters=COMPARED, responses={(200, "image/png"): bytes},
               summary="The difference of two versions: b's label map, paled, with the pixels whose label differs "
                       "from a's in magenta (one canvas, at most 1,024 px a side)")
@api_view(["GET"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
def procedure_compare_picture(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    a, b, diff = versions.compare(proc, request.query_params.get("a"), request.query_params.get("b"))
    return _cacheable(HttpResponse(diff["png"], content_type="image/png"), f'"{a.digest}-{b.digest}"', proc)


@extend_schema(request=SaveAsNewSerializer, responses={201: ProcedureSerializer},
               summary="Save as a new procedure: yours, private, whose parent is this one (kept with its photo as a "
                       "fork keeps it), holding 'data' (an edited tree or a variation; default: this one's tree) as "
                       "its second version, re-measured; titled from 'title', else from the variation that made it "
                       "or a running number, so that it is told apart from its parent")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def procedure_save_as_new(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    form = SaveAsNewSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    copy = versions.save_as_new(request.user, proc, form.validated_data.get("data"),
                                form.validated_data.get("title", ""))
    return Response(ProcedureSerializer(copy, context={"request": request}).data, status=status.HTTP_201_CREATED)
