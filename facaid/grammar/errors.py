"""The error of an invalid procedure, naming the node at fault."""

from __future__ import annotations


class ProcedureError(ValueError):
    """An invalid procedure; the message names the node by its path, e.g. ``root/2/0``."""

    def __init__(self, path: str, message: str):
        super().__init__(f"node {path}: {message}")
        self.path = path
