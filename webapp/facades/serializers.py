"""JSON shapes of the API. Segmentations and procedures are validated by the facaid library, whose messages
name the offending field or grammar node."""

from __future__ import annotations

from datetime import datetime

from django.contrib.auth.models import AnonymousUser
from django.core.validators import ProhibitNullCharactersValidator
from django.http import QueryDict
from django.utils import timezone
from rest_framework import serializers

from facaid.defaults import DEFAULT_K, MAX_K, STRUCTURES
from facaid.formats import interchange
from facaid.formats.cga import MAX_SCALE
from facaid.grammar.procedure import MAX_NODES
from facaid.numbers import finite
from facaid.segmentation import MAX_SIDE
from webapp.facades import access, disclosure
from webapp.facades.models import REAL_SIZE_M, Job, Photo, Procedure, ProcedureVersion, Segmentation, Visibility
from webapp.facades.parsing import parse_procedure
from webapp.facades.services import jobs, sharing


class TextField(serializers.CharField):
    """Text, and only text: DRF's CharField would store a number or a boolean sent as a title as its string."""

    default_error_messages = {"invalid": "Not text: give a string."}

    def to_internal_value(self, data):
        if not isinstance(data, str):
            self.fail("invalid")
        return super().to_internal_value(data)


def title_field() -> TextField:
    return TextField(max_length=200, required=False, allow_blank=True)


def _json_body(field: serializers.Field) -> bool:
    """Whether ``field`` reads a JSON body (a form or multipart body sends every number as text)."""
    return not isinstance(getattr(field.root, "initial_data", None), QueryDict)


def _not_a_number(field: serializers.Field, data) -> None:
    """Refuse a boolean (which Python counts as 0 or 1) and, in a JSON body, a number written as a string."""
    if isinstance(data, bool):
        field.fail("boolean")
    if isinstance(data, str) and _json_body(field):
        field.fail("string")


class NumberField(serializers.FloatField):
    """A finite JSON number: not a boolean, not a string (DRF's FloatField takes ``true`` as 1 and ``"5"`` as 5),
    not infinity, and no 500 for an integer too large for a float (DRF's raises OverflowError)."""

    default_error_messages = {"invalid": "A finite number is required.",
                              "boolean": "A number is required, not a boolean.",
                              "string": "A number is required, not a string: write it without quotes."}

    def to_internal_value(self, data):
        _not_a_number(self, data)
        try:
            value = super().to_internal_value(data)
        except OverflowError:
            self.fail("invalid")
        if not finite(value):
            self.fail("invalid")
        return value


class WholeNumberField(serializers.IntegerField):
    """A whole JSON number: not a boolean, not a string (DRF's IntegerField takes ``"5"`` as 5)."""

    default_error_messages = {"boolean": "A whole number is required, not a boolean.",
                              "string": "A whole number is required, not a string: write it without quotes."}

    def to_internal_value(self, data):
        _not_a_number(self, data)
        return super().to_internal_value(data)


class StrictBooleanField(serializers.BooleanField):
    """``true`` or ``false`` in a JSON body: DRF's BooleanField also takes 0, 1, "true", "yes" and "on", so that
    ``"save": 0`` passed as a boolean (a form or multipart body sends its booleans as text and is read as before)."""

    default_error_messages = {"invalid": "A boolean is required: true or false."}

    def to_internal_value(self, data):
        if not isinstance(data, bool) and _json_body(self):
            self.fail("invalid")
        return super().to_internal_value(data)


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


def _viewer(serializer: serializers.Serializer):
    """The user the answer is for: the request's, else anonymous (who is shown the least)."""
    request = serializer.context.get("request")
    return request.user if request is not None else AnonymousUser()


class ProcedureSerializer(serializers.ModelSerializer):
    owner = serializers.CharField(source="owner.username", read_only=True)
    parent = serializers.SerializerMethodField()
    photo = serializers.SerializerMethodField()
    segmentation = serializers.SerializerMethodField()
    version = serializers.SerializerMethodField(help_text="the current version's number (versions/ lists them)")
    photo_shared = serializers.SerializerMethodField(
        help_text="for the owner: whether those who may see the procedure see its photo and overlay too (null: no "
                  "photo, or not the owner)")
    viewers_see = serializers.SerializerMethodField(help_text="for the owner: what others see, in a sentence")

    class Meta:
        model = Procedure
        fields = ["code", "owner", "title", "visibility", "version", "accuracy", "metrics", "metres_per_pixel",
                  "scale_from", "parent", "photo", "segmentation", "photo_shared", "viewers_see", "data", "created",
                  "updated"]
        read_only_fields = ["code", "owner", "version", "accuracy", "metrics", "metres_per_pixel", "scale_from",
                            "parent", "photo", "segmentation", "photo_shared", "viewers_see", "created", "updated"]

    def get_version(self, proc: Procedure) -> int | None:
        current = proc.current_version()
        return current.version if current else None

    # links to other objects are shown only to those who may see them (a fork of a procedure made private later
    # does not reveal its parent; a public procedure does not reveal its private photo)
    def _user(self):
        return _viewer(self)

    def to_representation(self, proc: Procedure) -> dict:
        """As the viewer is shown it: to one who may not see the photo, nothing of it or of its segmentation (no
        figure, no title taken from the photo's, no accuracy in the tree's meta: `disclosure`)."""
        out = super().to_representation(proc)
        user = self._user()
        if disclosure.hidden(user, proc):
            out["title"] = disclosure.title(user, proc)
            out["accuracy"] = None
            if "metrics" in out:
                out["metrics"] = disclosure.metrics(proc.metrics)
            if "data" in out:
                out["data"] = disclosure.tree(out["data"])
        return out

    def get_parent(self, proc: Procedure) -> str | None:
        visible = proc.parent_id and access.parent_named_to(self._user(), proc, proc.parent)
        return str(proc.parent.code) if visible else None

    def get_photo(self, proc: Procedure) -> str | None:
        return str(proc.photo.code) if access.photo_visible_to(self._user(), proc.photo) else None

    def get_photo_shared(self, proc: Procedure) -> bool | None:
        return sharing.photo_shared(proc) if self._user().id == proc.owner_id else None

    def get_viewers_see(self, proc: Procedure) -> str | None:
        return sharing.viewers_see(proc) if self._user().id == proc.owner_id else None

    def get_segmentation(self, proc: Procedure) -> str | None:
        visible = proc.segmentation_id and access.photo_visible_to(self._user(), proc.photo)
        return str(proc.segmentation.code) if visible else None


class ProcedureSummarySerializer(ProcedureSerializer):
    class Meta(ProcedureSerializer.Meta):
        fields = ["code", "owner", "title", "visibility", "accuracy", "parent", "created"]


class ProcedureVersionSummarySerializer(serializers.ModelSerializer):
    """A version as the history lists it: its figures, what made it, and links to its picture and its tree."""

    picture = serializers.SerializerMethodField()
    url = serializers.SerializerMethodField()

    class Meta:
        model = ProcedureVersion
        fields = ["version", "kind", "note", "based_on", "warning", "accuracy", "metrics", "digest", "created",
                  "picture", "url"]
        read_only_fields = fields

    def to_representation(self, version: ProcedureVersion) -> dict:
        """As the viewer is shown it (the version's procedure set): to one who may not see the photo, no figure of
        its segmentation and no note naming the photo (`disclosure`)."""
        out = super().to_representation(version)
        user, proc = _viewer(self), version.procedure
        if disclosure.hidden(user, proc):
            out.update(accuracy=None, metrics=disclosure.metrics(version.metrics), warning="",
                       note=disclosure.note(user, proc, version.note))
            if "data" in out:
                out["data"] = disclosure.tree(out["data"])
        return out

    def _base(self, version: ProcedureVersion) -> str:
        return f"/api/v1/procedures/{version.procedure.code}/versions/{version.version}/"

    def get_picture(self, version: ProcedureVersion) -> str:
        return f"{self._base(version)}labels.png"

    def get_url(self, version: ProcedureVersion) -> str:
        return self._base(version)


class ProcedureVersionSerializer(ProcedureVersionSummarySerializer):
    data = serializers.JSONField(read_only=True, help_text="the version's tree (a procedure JSON)")

    class Meta(ProcedureVersionSummarySerializer.Meta):
        fields = [*ProcedureVersionSummarySerializer.Meta.fields, "data"]
        read_only_fields = fields


class SaveAsNewSerializer(serializers.Serializer):
    """A title and a tree; saving as a new procedure takes the procedure's own tree and a title of its own when
    they are left out."""

    title = title_field()
    data = serializers.JSONField(required=False, help_text="a procedure JSON (validated)")

    def validate_data(self, value):
        return parse_procedure(value).to_dict()


class ProcedureWriteSerializer(SaveAsNewSerializer):
    visibility = serializers.ChoiceField(Visibility.choices, required=False)
    metres_per_pixel = NumberField(
        required=False, allow_null=True,
        help_text=f"the procedure's own scale, metres per pixel (> 0, at most {MAX_SCALE:g}; null: none), the scale "
                  "of its metric downloads; kept across edits, and by its forks")

    def validate_metres_per_pixel(self, value):
        if value is not None and not 0 < value <= MAX_SCALE:
            raise serializers.ValidationError(f"metres_per_pixel must be a number > 0 and at most {MAX_SCALE:g}, "
                                              "or null for none")
        return value

    def validate(self, attrs):
        if "metres_per_pixel" in attrs:  # where it came from, said in the files
            attrs["scale_from"] = "given by its owner" if attrs["metres_per_pixel"] is not None else ""
        return attrs


class ProcedureEditSerializer(ProcedureWriteSerializer):
    share_photo = StrictBooleanField(
        required=False,
        help_text="share the procedure's photo (yours) as widely as the procedure, so that viewers see the overlay")


class JobSerializer(serializers.ModelSerializer):
    segmentation = serializers.SerializerMethodField(
        help_text="the segmentation it reconstructs; null once its photo is not shared with you (a fork's re-run "
                  "whose photo its owner made private)")
    result = serializers.SerializerMethodField()
    state_since = serializers.SerializerMethodField(help_text="when the job entered its status")
    state_seconds = serializers.SerializerMethodField(help_text="how long it has been in its status, in seconds")
    note = serializers.SerializerMethodField(help_text="what is happening to a job that is late: waiting for a "
                                                       "worker, or a worker that stopped reporting; else empty")

    class Meta:
        model = Job
        fields = ["code", "kind", "status", "progress", "stage", "message", "attempts", "params", "segmentation",
                  "result", "result_version", "created", "started", "finished", "state_since", "state_seconds",
                  "note"]
        read_only_fields = fields

    def get_segmentation(self, job: Job) -> str | None:
        return str(job.segmentation.code) if access.photo_visible_to(_viewer(self), job.segmentation.photo) else None

    def get_result(self, job: Job) -> str | None:
        return str(job.result.code) if job.result_id else None

    def _state(self, job: Job) -> tuple:
        if getattr(job, "_state_now", None) is None:
            job._state_now = timezone.now()
            job._state = jobs.state(job, job._state_now)
        return job._state

    def get_state_since(self, job: Job) -> datetime:
        return self._state(job)[0]

    def get_state_seconds(self, job: Job) -> int:
        since = self._state(job)[0]
        return max(0, int((job._state_now - since).total_seconds()))

    def get_note(self, job: Job) -> str:
        return self._state(job)[1]


def k_field() -> WholeNumberField:
    return WholeNumberField(min_value=1, max_value=MAX_K, default=DEFAULT_K,
                            help_text="candidates decoded and compared")


MAX_PREFIX_NODES = MAX_NODES  # a prefix keeps at most the whole tree


class JobCreateSerializer(serializers.Serializer):
    segmentation = serializers.UUIDField()
    k = k_field()
    seed = WholeNumberField(min_value=0, max_value=2**31 - 1, default=0)
    prefix_procedure = serializers.UUIDField(required=False, allow_null=True, default=None)
    prefix_nodes = WholeNumberField(min_value=0, max_value=MAX_PREFIX_NODES, default=0)
    structure = serializers.ChoiceField(
        STRUCTURES, default="editable",
        help_text="which procedure of a real facade becomes current: editable (floors of tiles with exceptions, "
                  "what the named parameters edit) or exact (the annotation as drawn); the other is kept as an "
                  "earlier version")


class RerunSerializer(serializers.Serializer):
    """A re-run keeps the procedure's first ``nodes`` nodes (breadth first); the same integers as a job's."""

    nodes = WholeNumberField(min_value=1, max_value=MAX_PREFIX_NODES, default=1)
    k = k_field()


class VariationsSerializer(serializers.Serializer):
    n = WholeNumberField(min_value=1, max_value=32, default=8)
    seed = WholeNumberField(min_value=0, max_value=2**31 - 1, default=0)
    ranges = serializers.DictField(
        child=serializers.ListField(child=NumberField(), min_length=2, max_length=2), required=False,
        help_text="named parameter -> [low, high], e.g. {\"floors\": [4, 7]}: each variant draws them instead")
    include_unchecked = StrictBooleanField(
        default=False, help_text="vary the counts whose edits are not clean too (a parameter's checked false); by "
                                 "default they are left out, and the answer's left_out says which and why")


class ParametersSerializer(serializers.Serializer):
    values = serializers.DictField(child=NumberField(), allow_empty=True,
                                   help_text="named parameters to set, e.g. {\"floors\": 6}")
    save = StrictBooleanField(default=False, help_text="save the result as the procedure's next version "
                                                      "(owner only); else it is only returned")
    data = serializers.JSONField(required=False, help_text="the tree to edit (a procedure JSON, validated; default "
                                                           "the procedure's saved one): the page's unsaved edits")

    def validate_data(self, value):
        return parse_procedure(value).to_dict()


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
