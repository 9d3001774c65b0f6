"""Building and loading the C libraries of `facaid.native`: compiled once per source, flags and CPU into the cache,
loaded with ctypes, or None where they cannot be had."""


from __future__ import annotations

import ctypes
import hashlib
import logging
import os
import shutil
import subprocess
import tempfile
from collections.abc import Callable
from pathlib import Path

log = logging.getLogger(__name__)

FLAGS = ["-O3", "-march=native", "-shared", "-fPIC", "-std=c99"]
# the step may fuse multiply-adds (its logits are checked to 1e-5); the executor must round as Python does
EXTRA_FLAGS = {"step": ["-ffp-contract=fast"], "rects": ["-ffp-contract=off"]}
_loaded: dict[str, ctypes.CDLL | None] = {}


def cache_dir() -> Path:
    return Path(os.environ.get("FACAID_CACHE") or Path.home() / ".cache" / "facaid") / "native"


def _cpu_flags() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            return next((line for line in f if line.startswith("flags")), "")
    except OSError:
        return ""


def build(name: str, compiler: str | None = None) -> Path:
    """Compile ``<name>.c`` of this package into the cache (once per source, flags and CPU) and return the
    library's path; raises RuntimeError when it cannot."""
    compiler = compiler or os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not compiler:
        raise RuntimeError("no C compiler found (cc or gcc, or set CC)")
    source_path = Path(__file__).with_name(f"{name}.c")
    source = source_path.read_bytes()
    flags = FLAGS + EXTRA_FLAGS.get(name, [])
    key = hashlib.sha256(source + " ".join(flags).encode() + _cpu_flags().encode()).hexdigest()[:16]
    out = cache_dir() / f"{name}-{key}.so"
    if out.exists():
        return out
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".so", dir=out.parent)
    os.close(fd)
    try:
        done = subprocess.run([compiler, *flags, "-o", tmp, str(source_path), "-lm"], capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"{compiler} failed: {done.stderr.strip()[:2000]}")
        os.replace(tmp, out)  # atomic: parallel builds (test workers) each write their own file first
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return out


def load(name: str, declare: Callable[[ctypes.CDLL], None]) -> ctypes.CDLL | None:
    """The library ``name``, built if needed and its functions declared by ``declare``; None (logged once)
    when it cannot be had or ``FACAID_NATIVE=0`` switches native code off."""
    if os.environ.get("FACAID_NATIVE", "1") == "0":
        return None
    if name not in _loaded:
        _loaded[name] = None
        try:
            lib = ctypes.CDLL(str(build(name)))
            declare(lib)
            _loaded[name] = lib
        except (RuntimeError, OSError) as exc:
            log.warning("native %s unavailable, keeping the Python path: %s", name, exc)
    return _loaded[name]


__all__ = ["EXTRA_FLAGS", "FLAGS", "build", "cache_dir", "load"]
