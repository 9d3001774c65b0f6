"""Validates a CityJSON file as the official validator (cjval) does, without it: `facaid validate-cityjson`.

cjval, the CityJSON project's validator, is a Rust program; its Python bindings (cjvalpy) have no wheel for this
platform and `cjio validate` needs them, so FaçAID ships the checks a person would run:

- errors: the JSON syntax; the official schema of the file's version, CityJSON 2.0.2 or 1.0.3 (the minified
  schema files of github.com/cityjson/specs, CC0, in `schemas/` here), which names every unknown city object or
  semantic type, a missing member and a wrong LoD; then, as cjval, vertex indices out of range, semantics arrays
  whose shape is not the geometry's, and parents and children that do not name each other;
- warnings, as cjval: duplicate vertices and unused vertices.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cache
from importlib.resources import files
from typing import Any

SCHEMAS = {"2.0": "cityjson-2.0.2.min.schema.json", "1.0": "cityjson-1.0.3.min.schema.json"}
SHOWN = 20  # errors of one kind named before "and N more"
ONE = {"city objects": "city object", "vertices": "vertex", "surfaces": "surface"}
SURFACE_DEPTH = {  # geometry type -> how many list levels of its boundaries lie above a surface's rings
    "MultiSurface": 1, "CompositeSurface": 1, "Solid": 2, "MultiSolid": 3, "CompositeSolid": 3}


@dataclass
class Report:
    version: str | None = None
    errors: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    counts: dict[str, int] = field(default_factory=dict)

    @property
    def valid(self) -> bool:
        return not self.errors

    def summary(self) -> str:
        return ", ".join(f"{n} {what if n != 1 else ONE[what]}" for what, n in self.counts.items())


def _type_schema(branch: dict) -> dict | None:
    """What a ``oneOf`` branch asks of its instance's ``type`` (a const, an enum or a pattern), or None."""
    for part in [branch, *branch.get("allOf", [])]:
        wanted = part.get("properties", {}).get("type", {})
        if {"const", "enum", "pattern"} & set(wanted):
            return wanted
    return None


def _by_type(node: Any) -> Any:
    """The schema with every ``oneOf`` whose branches each ask for a ``type`` (a city object's, a geometry's)
    made an if/then per type: an instance is checked against its own type's branch alone. A ``oneOf`` checks every
    branch and, failing, names none (7 s and a 30 KB message for one wrong semantic surface on a facade); this
    names what is wrong inside the branch, as cjval does, in milliseconds."""
    if isinstance(node, list):
        return [_by_type(n) for n in node]
    if not isinstance(node, dict):
        return node
    node = {k: _by_type(v) for k, v in node.items()}
    branches = node.get("oneOf")
    if branches and all(isinstance(b, dict) and _type_schema(b) is not None for b in branches):
        kinds = [_type_schema(b) for b in branches]
        node.pop("oneOf")
        node.setdefault("allOf", []).extend(
            [{"required": ["type"], "properties": {"type": {"anyOf": kinds}}}]
            + [{"if": {"required": ["type"], "properties": {"type": kind}}, "then": branch}
               for kind, branch in zip(kinds, branches, strict=True)])
    return node


@cache
def _validator(version: str):
    import jsonschema_rs

    schema = json.loads((files("facaid.formats") / "schemas" / SCHEMAS[version]).read_text())
    return jsonschema_rs.validator_for(_by_type(schema))


def _schema_errors(version: str, doc: dict) -> list[str]:
    out = []
    for error in _validator(version).iter_errors(doc):
        where = "/".join(map(str, error.instance_path)) or "(root)"
        if error.instance_path and error.instance_path[-1] == "type" and "Of' keyword" in error.message:
            out.append(f"{where}: {error.instance!r} is not a type CityJSON {version} allows here")
        else:
            out.append(f"{where}: {error.message if len(error.message) <= 200 else error.message[:200] + '...'}")
    return out


def _limited(kind: str, problems: list[str]) -> list[str]:
    shown = [f"{kind}: {p}" for p in problems[:SHOWN]]
    return shown + ([f"{kind}: and {len(problems) - SHOWN} more"] if len(problems) > SHOWN else [])


def _indices(boundaries: Any):
    if isinstance(boundaries, list):
        for b in boundaries:
            yield from _indices(b)
    else:
        yield boundaries


def _shape(boundaries: list, depth: int) -> Any:
    """The semantics values' expected shape: the surface count at the bottom level, nested lists above it."""
    return len(boundaries) if depth == 1 else [_shape(b, depth - 1) for b in boundaries]


def _values_shape(values: Any, depth: int) -> Any:
    if not isinstance(values, list):
        return None
    return len(values) if depth == 1 else [_values_shape(v, depth - 1) for v in values]


def _geometry_problems(oid: str, geometries: list[dict], n_vertices: int, used: set[int]) -> tuple[list, list]:
    bad_index, bad_semantics = [], []
    for g, geometry in enumerate(geometries):
        where = f"{oid!r} geometry {g}"
        indices = list(_indices(geometry.get("boundaries", [])))  # a GeometryInstance's: its one reference point
        out = [i for i in indices if not 0 <= i < n_vertices]
        if out:
            bad_index.append(f"{where}: {len(out)} indices out of 0..{n_vertices - 1}, the first {out[0]}")
        used.update(i for i in indices if 0 <= i < n_vertices)
        depth = SURFACE_DEPTH.get(geometry.get("type"))
        semantics = geometry.get("semantics")
        if depth is None or semantics is None:
            continue
        expected = _shape(geometry["boundaries"], depth)
        found = _values_shape(semantics.get("values"), depth)
        if found != expected:
            bad_semantics.append(f"{where}: its values are shaped {found}, its surfaces {expected}")
        count = len(semantics.get("surfaces", []))
        wrong = [v for v in _indices(semantics.get("values", [])) if v is not None and not 0 <= v < count]
        if wrong:
            bad_semantics.append(f"{where}: values name surface {wrong[0]}, of {count}")
    return bad_index, bad_semantics


def check_cityjson(text: str | bytes) -> Report:
    """The `Report` of a CityJSON document's text (see the module's docstring)."""
    report = Report()
    try:
        doc = json.loads(text)
    except (ValueError, UnicodeDecodeError) as exc:
        report.errors.append(f"json syntax: {exc}")
        return report
    if not isinstance(doc, dict) or doc.get("type") != "CityJSON":
        what = (f"its type is {doc['type']!r}" if isinstance(doc, dict) and "type" in doc
                else "it has no type" if isinstance(doc, dict) else f"it is a JSON {type(doc).__name__}")
        report.errors.append(f"not a CityJSON file: {what}, not 'CityJSON'")
        return report
    report.version = version = str(doc.get("version"))
    if version not in SCHEMAS:
        report.errors.append(f"version {version}: this validator knows {' and '.join(SCHEMAS)} "
                             "(`cjio FILE upgrade save NEW` converts 1.1 to 2.0)")
        return report
    schema_errors = _schema_errors(version, doc)
    if schema_errors:
        report.errors += _limited(f"schema {SCHEMAS[version].split('.min')[0]}", schema_errors)
        return report  # the checks below read the structure the schema guarantees
    objects, vertices = doc["CityObjects"], doc["vertices"]
    used: set[int] = set()
    bad_index, bad_semantics, family = [], [], []
    for oid, obj in objects.items():
        index, semantics = _geometry_problems(oid, obj.get("geometry", []), len(vertices), used)
        bad_index += index
        bad_semantics += semantics
        for child in obj.get("children", []):
            if child not in objects:
                family.append(f"{oid!r} names child {child!r}, which is not a city object")
            elif oid not in objects[child].get("parents", []):
                family.append(f"{oid!r} names child {child!r}, which does not name it as a parent")
        for parent in obj.get("parents", []):
            if parent not in objects:
                family.append(f"{oid!r} names parent {parent!r}, which is not a city object")
            elif oid not in objects[parent].get("children", []):
                family.append(f"{oid!r} names parent {parent!r}, which does not name it as a child")
    report.errors += (_limited("wrong vertex index", bad_index) + _limited("semantics arrays", bad_semantics)
                      + _limited("parents and children", family))
    duplicates = len(vertices) - len({tuple(v) for v in vertices})
    if duplicates:
        report.warnings.append(f"duplicate vertices: {duplicates}")
    if len(used) < len(vertices):
        report.warnings.append(f"unused vertices: {len(vertices) - len(used)}")
    surfaces = sum(len(g.get("boundaries", [])) for o in objects.values() for g in o.get("geometry", [])
                   if g.get("type") in ("MultiSurface", "CompositeSurface"))
    report.counts = {"city objects": len(objects), "vertices": len(vertices), "surfaces": surfaces}
    return report
