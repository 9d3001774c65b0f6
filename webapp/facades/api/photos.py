"""The API's photos: upload, list, read, change, delete, the image file, rectification and its proposed corners,
and completion of a segmentation drawn on the photo."""

from __future__ import annotations

from django.db.models import OuterRef, Subquery
from django.http import FileResponse
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import status
from rest_framework.decorators import (
    api_view,
    parser_classes,
    permission_classes,
    throttle_classes,
)
from rest_framework.exceptions import ValidationError
from rest_framework.parsers import FormParser, MultiPartParser
from rest_framework.permissions import AllowAny, IsAuthenticated
from rest_framework.response import Response

from webapp.facades import access
from webapp.facades.api.common import (
    page,
)
from webapp.facades.jsonbody import JSONParser
from webapp.facades.models import (
    Photo,
    Segmentation,
)
from webapp.facades.serializers.photos import (
    PhotoSerializer,
    PhotoUploadSerializer,
    RectifySerializer,
)
from webapp.facades.services.photos import create_photo, delete_photo, propose_corners, rectify_photo
from webapp.facades.services.segmentations import complete_segmentation
from webapp.facades.throttling import HEAVY


@extend_schema(methods=["GET"], responses=PhotoSerializer(many=True), summary="Your photos")
@extend_schema(methods=["POST"], request={"multipart/form-data": PhotoUploadSerializer},
               responses={201: PhotoSerializer}, summary="Upload a photo (JPEG, PNG or WebP)")
@api_view(["GET", "POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
@parser_classes([MultiPartParser, FormParser])
def photos(request):
    if request.method == "GET":
        latest = Segmentation.objects.filter(photo=OuterRef("pk")).order_by("-version").values("code")[:1]
        photos = Photo.objects.filter(owner=request.user).select_related("owner").annotate(
            latest_segmentation_code=Subquery(latest))
        return page(request, photos, PhotoSerializer)
    form = PhotoUploadSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    photo = create_photo(request.user, form.validated_data["image"], form.validated_data.get("title", ""),
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
        delete_photo(photo)
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
    rectify_photo(photo, form.validated_data["corners"])
    return Response(PhotoSerializer(photo).data)


@extend_schema(request=None, responses={200: dict},
               summary="Propose the facade's four corners from the photo's lines and vanishing points "
                       "(facaid.photo.corners.propose_corners): {'corners': [[x, y] x 4] (top-left, top-right, "
                       "bottom-right, "
                       "bottom-left, in the original photo's pixels, as rectify takes them), 'confidence' (0..1: the "
                       "share of the four sides that detected lines cover), 'notes', 'lines'}; nothing is stored")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
def photo_propose_corners(request, code):
    return Response(propose_corners(access.get_rw_photo_for_user(request.user, code)))


@extend_schema(request={"application/json": dict}, responses={200: dict},
               summary="Propose the elements not drawn yet (facaid.complete): the body is the segmentation drawn so "
                       "far, with optional 'rejected' rectangles and 'min_score'; returns {'proposals': [{label, x0, "
                       "y0, x1, y1, score, reason}], 'dimmed': [the places scored under min_score, from 0.3], "
                       "'tried': [what was tried, in words, where nothing is proposed]}; with 'unit', the copies "
                       "of that unit: {'proposals'}; nothing is stored")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def photo_complete(request, code):
    photo = access.get_photo_for_user(request.user, code)
    if not isinstance(request.data, dict):
        raise ValidationError({"segmentation": "must be a JSON object"})
    return Response(complete_segmentation(photo, request.data))

