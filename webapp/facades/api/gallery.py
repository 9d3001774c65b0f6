"""The API's public gallery: the public procedures, newest first, the same for everyone."""

from __future__ import annotations

from drf_spectacular.utils import extend_schema
from rest_framework.decorators import (
    api_view,
    authentication_classes,
    permission_classes,
)
from rest_framework.permissions import AllowAny
from rest_framework.response import Response

from webapp.facades import access
from webapp.facades.api.common import (
    page,
)
from webapp.facades.serializers.procedures import (
    ProcedureSummarySerializer,
)
from webapp.facades.services.gallery import gallery_page


@extend_schema(responses=ProcedureSummarySerializer(many=True), auth=[],
               summary="Public procedures, newest first (the same for everyone)")
@api_view(["GET"])
@authentication_classes([])  # the listing is the public's: no session or token is read
@permission_classes([AllowAny])
def gallery(request):
    """Served from each process's memory while no procedure has changed (`webapp.facades.services.gallery`)."""
    where = (request.scheme, request.get_host(), request.get_full_path())  # the page's links are made from it
    return Response(gallery_page(
        where, lambda: page(request, access.public_procedures(), ProcedureSummarySerializer).data))
