"""The API's shapes of segmentations: a version (with or without its rectangles) and an annotation file to convert
into the segmentation contract."""

from __future__ import annotations

from django.core.validators import ProhibitNullCharactersValidator
from rest_framework import serializers

from facaid.formats import interchange
from facaid.segmentation import MAX_SIDE
from webapp.facades.models import Segmentation
from webapp.facades.serializers.base import TextField, WholeNumberField


class SegmentationSerializer(serializers.ModelSerializer):
    photo = serializers.UUIDField(source="photo.code", read_only=True)

    class Meta:
        model = Segmentation
        fields = ["code", "photo", "version", "rect_count", "data", "created"]
        read_only_fields = fields


class SegmentationSummarySerializer(SegmentationSerializer):
    """A version as lists show it: its rectangles are fetched one version at a time (up to 20,000 each)."""

    class Meta(SegmentationSerializer.Meta):
        fields = ["code", "photo", "version", "rect_count", "created"]
        read_only_fields = fields


class AnnotationTextField(TextField):
    """An annotation file's text; a binary file (the photo picked instead) is named as such, not as "null
    characters"."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.validators = [v for v in self.validators if not isinstance(v, ProhibitNullCharactersValidator)]

    def to_internal_value(self, data):
        text = super().to_internal_value(data)
        if message := interchange.not_annotations(text):
            raise serializers.ValidationError(message)
        return text


class ConvertSerializer(serializers.Serializer):
    text = AnnotationTextField(trim_whitespace=False, help_text="the annotation file's content")
    format = serializers.ChoiceField(interchange.FORMATS, required=False,
                                     help_text="its format (default: found from the content)")
    image = TextField(max_length=1000, required=False,
                      help_text="of a COCO or CVAT file of several images, the one to read: its file name or id")
    width = WholeNumberField(min_value=1, max_value=MAX_SIDE, required=False,
                             help_text="with height: of several images, read the only one of this size")
    height = WholeNumberField(min_value=1, max_value=MAX_SIDE, required=False)
