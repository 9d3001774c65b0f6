"""Every benchmark under bench/ imports (what the README's figures are measured with): a module moved or a name a
package no longer exports breaks a figure's command, which no other test runs (a review found bench_assist.py so)."""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = sorted((ROOT / "bench").glob("bench_*.py"))


@pytest.mark.parametrize("path", SCRIPTS, ids=[p.stem for p in SCRIPTS])
def test_the_benchmark_imports_and_has_a_main(path, monkeypatch):
    monkeypatch.syspath_prepend(str(path.parent))  # as run: a script's folder is on its path (bench_site's helpers)
    spec = importlib.util.spec_from_file_location(f"bench_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # its imports; main() runs only as a script
    assert callable(getattr(module, "main", None)), path.name
