"""The API's shapes of a procedure's versions: as the history lists them (their figures, what made them, links to
their picture and tree) and one with its tree, as the viewer is shown them (`disclosure`)."""

from __future__ import annotations

from rest_framework import serializers

from webapp.facades import disclosure
from webapp.facades.models import ProcedureVersion
from webapp.facades.serializers.base import viewer


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
        user, proc = viewer(self), version.procedure
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
