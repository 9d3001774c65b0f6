"""Settings from the environment, through helpers that fail loudly on a malformed value: the site's, and the worker's
too (`worker.app` reads its limits here), so both read a variable the same way and name it when it is wrong; and the
throttle rates only the site reads."""

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



RATE_PERIODS = ("s", "m", "h", "d")


def env_rate(name: str, default: str | None) -> str | None:
    """A throttle rate as Django REST framework reads it ("120/min": a count per s, m, h or d; only the period's
    first letter counts), or None for "none" / "off" (no limit)."""
    raw = os.environ.get(name)
    if raw is None or raw.strip() == "":
        return default
    value = raw.strip().lower()
    if value in ("none", "off"):
        return None
    count, _, period = value.partition("/")
    if not count.isdigit() or int(count) < 1 or not period or period[0] not in RATE_PERIODS:
        raise EnvError(f"{name} must be a rate like 120/min (a count per s, min, hour or day) or 'none', "
                       f"got {raw!r}")
    return value


__all__ = ["EnvError", "env_bool", "env_float", "env_int", "env_list", "env_rate", "env_seconds", "env_str"]
