"""The API's shapes of photos: a photo as read and changed (its title, visibility and real size), an upload, the
corners that rectify it."""

from __future__ import annotations

from rest_framework import serializers

from webapp.facades.models import REAL_SIZE_M, Photo, Visibility
from webapp.facades.serializers.base import NumberField, title_field


def real_size_field(side: str) -> NumberField:
    lo, hi = REAL_SIZE_M
    return NumberField(min_value=lo, max_value=hi, required=False, allow_null=True,
                       help_text=f"the facade's real {side} in metres ({lo:g} to {hi:g}; null: none), "
                                 "the scale of its CGA rules and mesh; setting one clears the other")


class PhotoSerializer(serializers.ModelSerializer):
    owner = serializers.CharField(source="owner.username", read_only=True)
    title = title_field()
    image = serializers.SerializerMethodField()
    rectified = serializers.SerializerMethodField()
    segmentation = serializers.SerializerMethodField()
    real_width_m = real_size_field("width")
    real_height_m = real_size_field("height")
    metres_per_pixel = serializers.SerializerMethodField(
        help_text="the real size over the working (rectified) image's pixels; null without a real size")

    class Meta:
        model = Photo
        fields = ["code", "owner", "title", "width", "height", "visibility", "image", "rectified", "corners",
                  "real_width_m", "real_height_m", "metres_per_pixel", "segmentation", "created"]
        read_only_fields = ["code", "owner", "width", "height", "image", "rectified", "corners", "created"]

    def validate(self, attrs):
        width, height = attrs.get("real_width_m"), attrs.get("real_height_m")
        if width is not None and height is not None:
            raise serializers.ValidationError({"real_height_m": "give the real width or the real height, not both"})
        if width is not None:  # one real size at a time: the other would contradict it once the photo is cropped
            attrs["real_height_m"] = None
        elif height is not None:
            attrs["real_width_m"] = None
        return attrs

    def get_metres_per_pixel(self, photo: Photo) -> float | None:
        return photo.metres_per_pixel()

    def update(self, photo: Photo, validated_data: dict) -> Photo:
        """The photo changed; where its real size did, its owner's procedures made from it take the new scale."""
        resized = {"real_width_m", "real_height_m"} & validated_data.keys()
        photo = super().update(photo, validated_data)
        if resized:
            photo.rescale_procedures()
        return photo

    def get_image(self, photo: Photo) -> str:
        return f"/api/v1/photos/{photo.code}/image"

    def get_rectified(self, photo: Photo) -> str | None:
        return f"/api/v1/photos/{photo.code}/image?rectified=1" if photo.rectified else None

    def get_segmentation(self, photo: Photo) -> str | None:
        if hasattr(photo, "latest_segmentation_code"):  # annotated by lists: no query per photo
            code = photo.latest_segmentation_code
            return str(code) if code else None
        seg = photo.latest_segmentation()
        return str(seg.code) if seg else None


class PhotoUploadSerializer(serializers.Serializer):
    image = serializers.FileField(allow_empty_file=True)
    title = title_field()
    visibility = serializers.ChoiceField(Visibility.choices, default=Visibility.PRIVATE)


class RectifySerializer(serializers.Serializer):
    corners = serializers.ListField(
        child=serializers.ListField(child=NumberField(), min_length=2, max_length=2),
        min_length=4, max_length=4, help_text="[[x, y] x 4]: top-left, top-right, bottom-right, bottom-left")
