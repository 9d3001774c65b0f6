"""The API's versions of a procedure: list, read, their pictures, revert and compare."""

from __future__ import annotations

from django.http import HttpResponse
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import status
from rest_framework.decorators import (
    api_view,
    permission_classes,
    throttle_classes,
)
from rest_framework.permissions import AllowAny, IsAuthenticated
from rest_framework.response import Response

from facaid.grammar import to_segmentation
from webapp.facades import access, drawing
from webapp.facades.api.common import (
    cacheable,
)
from webapp.facades.paging import Pagination
from webapp.facades.parsing import parse_procedure
from webapp.facades.serializers.procedures import ProcedureSerializer
from webapp.facades.serializers.versions import ProcedureVersionSerializer, ProcedureVersionSummarySerializer
from webapp.facades.services import versions
from webapp.facades.throttling import HEAVY


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
    return pager.get_paginated_response(ProcedureVersionSummarySerializer(
        page, many=True, context={"request": request}).data)


@extend_schema(responses=ProcedureVersionSerializer, summary="One version of the procedure, with its tree")
@api_view(["GET"])
@permission_classes([AllowAny])
def procedure_version(request, code, number):
    proc = access.get_procedure_for_user(request.user, code)
    return Response(ProcedureVersionSerializer(versions.get_version(proc, number), context={"request": request}).data)


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
        return cacheable(HttpResponse(status=304), etag, proc)
    seg = to_segmentation(parse_procedure(version.data))
    return cacheable(HttpResponse(drawing.label_map_png(seg, drawing.COMPARE_SIDE), content_type="image/png"),
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
    for key, version, (width, height) in zip(("a", "b"), (a, b), diff["sizes"], strict=True):
        shown = ProcedureVersionSummarySerializer(version, context={"request": request}).data
        sides[key] = {**shown, "width": width, "height": height}
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
    return cacheable(HttpResponse(diff["png"], content_type="image/png"), f'"{a.digest}-{b.digest}"', proc)

