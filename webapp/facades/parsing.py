"""Reading what a request sends into the library's objects, for the API's serializers, the services and the pages
alike: a bad document is `Invalid` naming the field (``segmentation``, ``data``), whose message is the library's,
naming the offending field or grammar node."""

from __future__ import annotations

from facaid.grammar import Procedure as ProcedureTree
from facaid.grammar.procedure import ProcedureError
from facaid.grammar.procedure import parse_procedure as parse_tree
from facaid.segmentation import Segmentation as SegmentationData
from webapp.facades.errors import Invalid


def parse_segmentation(data) -> SegmentationData:
    try:
        return SegmentationData.from_dict(data)
    except (ValueError, TypeError) as exc:
        raise Invalid(str(exc), "segmentation") from None


def parse_procedure(data, sent: bool = True) -> ProcedureTree:
    """A procedure JSON read into the library's tree; ``sent`` (the default): from a request, where a tree sure to
    cost too much is refused before it is read (`facaid.grammar.procedure.parse_procedure`)."""
    try:
        return parse_tree(data, sent=sent)
    except (ProcedureError, ValueError, TypeError, KeyError) as exc:
        raise Invalid(str(exc), "data") from None
