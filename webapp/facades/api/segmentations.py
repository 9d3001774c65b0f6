"""The API's segmentations: a photo's versions (ours, or COCO, LabelMe or CVAT files), its draft and its
segmentation as a file; one version; annotations converted without storing anything."""

from __future__ import annotations

from django.http import HttpResponse
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import status
from rest_framework.decorators import (
    api_view,
    parser_classes,
    permission_classes,
    throttle_classes,
)
from rest_framework.exceptions import NotAuthenticated
from rest_framework.permissions import AllowAny, IsAuthenticated
from rest_framework.response import Response

from facaid.formats import interchange
from webapp.facades import access
from webapp.facades.api.common import (
    ANNOTATIONS,
    IMPORT_PARAMETERS,
    TextXMLParser,
    XMLParser,
    file_format_param,
    page,
)
from webapp.facades.errors import Invalid
from webapp.facades.jsonbody import JSONParser
from webapp.facades.serializers.segmentations import (
    ConvertSerializer,
    SegmentationSerializer,
    SegmentationSummarySerializer,
)
from webapp.facades.services.segmentations import (
    add_segmentation,
    draft_of,
    drop_draft,
    read_annotations,
    save_draft,
    segmentation_file,
)
from webapp.facades.throttling import HEAVY


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
        return page(request, photo.segmentations.select_related("photo").defer("data").order_by("-version"),
                     SegmentationSummarySerializer)
    if not request.user.is_authenticated:
        raise NotAuthenticated()
    photo = access.get_rw_photo_for_user(request.user, code)
    seg, warnings = add_segmentation(photo, request.data, request.query_params.get("format"),
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
        return Response(_draft(save_draft(photo, request.data)))
    if request.method == "DELETE":
        drop_draft(photo)
        return Response(status=status.HTTP_204_NO_CONTENT)
    return Response(_draft(draft_of(photo)))


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
    name, content_type, body = segmentation_file(photo, request.query_params.get("format", "segmentation"),
                                                  request.query_params.get("version"))
    resp = HttpResponse(body, content_type=content_type)
    resp["Content-Disposition"] = f'attachment; filename="{name}"'
    return resp


@extend_schema(responses=SegmentationSerializer, summary="One segmentation version")
@api_view(["GET"])
@permission_classes([AllowAny])
def segmentation_detail(request, code):
    return Response(SegmentationSerializer(access.get_segmentation_for_user(request.user, code)).data)


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
        loaded = read_annotations(v["text"], v.get("format"), v.get("image"), size)
    except Invalid as exc:  # the file is the request's 'text'
        raise Invalid(exc.message, "text" if exc.field == "segmentation" else exc.field) from None
    return Response({"segmentation": loaded.segmentation.to_dict(), "format": loaded.format, "image": loaded.image,
                     "warnings": list(loaded.warnings)})

