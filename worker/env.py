"""Settings from the environment, through helpers that fail loudly on a malformed value: the worker's, and the
site's too (`webapp.env` builds on them), so both read a variable the same way and name it when it is wrong."""

from __future__ import annotations

import os


class EnvError(ValueError):
    """A malformed environment variable; the message names it and says what it takes."""


def env_str(name: str, default: str) -> str:
    return os.environ.get(name, default)


def env_bool(name: str, default: bool) -> bool:
    raw = os.environ.get(name)
    if raw is None or raw == "":
        return default
    value = raw.strip().lower()
    if value in ("1", "true", "yes", "on"):
        return True
    if value in ("0", "false", "no", "off"):
        return False
    raise EnvError(f"{name} must be a boolean (1/0, true/false), got {raw!r}")


def env_int(name: str, default: int, minimum: int | None = None) -> int:
    raw = os.environ.get(name)
    if raw is None or raw == "":
        return default
    try:
        value = int(raw)
    except ValueError:
        raise EnvError(f"{name} must be an integer, got {raw!r}") from None
    if minimum is not None and value < minimum:
        raise EnvError(f"{name} must be at least {minimum}, got {raw!r}")
    return value


def env_float(name: str, default: float, minimum: float = 0.0) -> float:
    raw = os.environ.get(name)
    if raw is None or raw == "":
        return default
    try:
        value = float(raw)
    except ValueError:
        raise EnvError(f"{name} must be a number, got {raw!r}") from None
    if not minimum <= value < float("inf"):
        raise EnvError(f"{name} must be a finite number of at least {minimum:g}, got {raw!r}")
    return value


def env_seconds(name: str, default: int) -> int | None:
    """A time limit in whole seconds; 0 turns it off (None)."""
    return env_int(name, default, minimum=0) or None


def env_list(name: str, default: list[str]) -> list[str]:
    raw = os.environ.get(name)
    if raw is None or raw.strip() == "":
        return default
    return [item.strip() for item in raw.split(",") if item.strip()]
