"""The ``facaid`` command line: ``facaid <command> --help`` describes each command. Each module holds a group of
commands, each handler beside the function that adds its parser."""

from facaid.cli.main import build_parser, main

__all__ = ["build_parser", "main"]
