"""The API's shapes of procedures: a procedure as the viewer is shown it (`disclosure`), in full or as lists show it,
and what the requests that store, edit, save as new, vary or set the named parameters of one send. Procedure JSON is
validated by the facaid library, whose messages name the offending field or grammar node."""

from __future__ import annotations

from rest_framework import serializers

from facaid.formats.cga import MAX_SCALE
from webapp.facades import access, disclosure
from webapp.facades.models import Procedure, Visibility
from webapp.facades.parsing import parse_procedure
from webapp.facades.serializers.base import NumberField, StrictBooleanField, WholeNumberField, title_field, viewer
from webapp.facades.services import sharing


def procedure_data(value) -> dict:
    """A procedure JSON validated (`parsing.parse_procedure`), as a field's value: a bad one raises its `Invalid`,
    which the API answers as every service's, ``{"data": <the library's message>}`` (not nested in DRF's field
    errors as ``{"data": {"data": ...}}``)."""
    return parse_procedure(value).to_dict()


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
        return viewer(self)

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


class SaveAsNewSerializer(serializers.Serializer):
    """A title and a tree; saving as a new procedure takes the procedure's own tree and a title of its own when
    they are left out."""

    title = title_field()
    data = serializers.JSONField(required=False, help_text="a procedure JSON (validated)")

    def validate_data(self, value):
        return procedure_data(value)


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
        return procedure_data(value)
