"""The API's reconstruction jobs: submit, list, read."""

from __future__ import annotations

from drf_spectacular.utils import extend_schema
from rest_framework import status
from rest_framework.decorators import (
    api_view,
    parser_classes,
    permission_classes,
)
from rest_framework.exceptions import PermissionDenied, ValidationError
from rest_framework.permissions import AllowAny, IsAuthenticated
from rest_framework.response import Response

from webapp.facades import access
from webapp.facades.api.common import (
    page,
)
from webapp.facades.jsonbody import JSONParser
from webapp.facades.models import (
    Job,
)
from webapp.facades.serializers.jobs import (
    JobCreateSerializer,
    JobSerializer,
)
from webapp.facades.services.jobs import submit_job


@extend_schema(methods=["GET"], responses=JobSerializer(many=True), summary="Your jobs, newest first")
@extend_schema(methods=["POST"], request=JobCreateSerializer, responses={202: JobSerializer},
               summary="Reconstruct a procedure from a segmentation (optionally continuing a procedure's "
                       "first nodes)")
@api_view(["GET", "POST"])
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def job_list(request):
    if request.method == "GET":
        return page(request, Job.objects.filter(owner=request.user).select_related(
            "segmentation__photo", "result").defer(*access.JOB_WITHOUT), JobSerializer)
    form = JobCreateSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    v = form.validated_data
    seg = access.get_segmentation_for_user(request.user, v["segmentation"])
    if seg.photo.owner != request.user:
        raise ValidationError({"segmentation": "fork the photo's procedure or upload your own photo to "
                                               "reconstruct it"})
    if access.is_demo(seg.photo):
        raise PermissionDenied(access.DEMO_READ_ONLY)
    prefix = access.get_procedure_for_user(request.user, v["prefix_procedure"]) if v["prefix_procedure"] else None
    job = submit_job(request.user, seg, v["k"], v["seed"], prefix, v["prefix_nodes"], v["structure"])
    return Response(JobSerializer(job, context={"request": request}).data, status=status.HTTP_202_ACCEPTED)


@extend_schema(responses=JobSerializer, summary="A job's status and progress")
@api_view(["GET"])
@permission_classes([AllowAny])
def job_detail(request, code):
    return Response(JobSerializer(access.get_job_for_user(request.user, code), context={"request": request}).data)

