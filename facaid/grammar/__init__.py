"""The FaçAID split grammar: procedures (derivation trees), their JSON form, and their execution."""

from facaid.grammar.execute import execute, to_segmentation
from facaid.grammar.layout import layout
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import GRAMMAR_VERSION, Procedure, ProcedureError, parse_procedure, validate

__all__ = [
    "GRAMMAR_VERSION",
    "Node",
    "Procedure",
    "ProcedureError",
    "Size",
    "execute",
    "layout",
    "parse_procedure",
    "to_segmentation",
    "validate",
]
