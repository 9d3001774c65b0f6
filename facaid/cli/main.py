"""The ``facaid`` command's parser, from each group's commands, and its entry point."""


from __future__ import annotations

import argparse
import sys

from facaid.cli import dataset, editing, exporting, learning, photos, reconstruction
from facaid.cli.common import CliError

COMMANDS = (  # the order of `facaid --help`
    dataset.add_generate, dataset.add_render, learning.add_train, learning.add_evaluate, learning.add_compare,
    reconstruction.add_reconstruct, reconstruction.add_complete, editing.add_vary, editing.add_params,
    exporting.add_cga_and_mesh, exporting.add_export, photos.add_rectify, exporting.add_convert,
    exporting.add_validate_cityjson, learning.add_evaluate_real, dataset.add_demo)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="facaid", description="FaçAID: facade segmentations to procedures.")
    sub = parser.add_subparsers(dest="command", required=True)
    for add in COMMANDS:
        add(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    from facaid.grammar.procedure import ProcedureError
    from facaid.segmentation import SegmentationError

    args = build_parser().parse_args(argv)
    try:
        args.func(args)
    except (CliError, ProcedureError, SegmentationError, ValueError, FileNotFoundError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


__all__ = ["COMMANDS", "build_parser", "main"]
