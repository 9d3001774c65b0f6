"""The API's shapes of reconstruction jobs: a job with its state (how long in it, what is happening to a late one),
and what submitting one or re-running a procedure sends."""

from __future__ import annotations

from datetime import datetime

from django.utils import timezone
from rest_framework import serializers

from facaid.defaults import DEFAULT_K, MAX_K, STRUCTURES
from facaid.grammar.procedure import MAX_NODES
from webapp.facades import access
from webapp.facades.models import Job
from webapp.facades.serializers.base import WholeNumberField, viewer
from webapp.facades.services import jobs


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
        return str(job.segmentation.code) if access.photo_visible_to(viewer(self), job.segmentation.photo) else None

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
