"""The product checks its own edits (issue 67): every tree the site saves has `floors` ± 1 and `bays` ± 1 tried on it
and judged as a person looks at the picture before and after (`facaid.editing.check.check_edits`), and the verdicts
are kept in the procedure's metrics under ``"edits"`` with the digest of the tree they judged, so that a record of
another tree (a stale one) is never shown: it is checked again, or said to be not checked.

A check executes four edited trees at full resolution and compares their label maps band by band, so it costs
what the tree's node instances and its pixels cost (`estimate`): about 0.2 s for a CMP facade, but 40 s for a
4,096 px square of two floors. A tree whose check would cost more than `CHECK_SECONDS` is not checked, and the
record says so and why; inside a request the check is reserved from its work budget first (`CHECK_WORK` units of
the tree's, and at most `LEAVE` of the CPU time it has left), and one the request cannot pay is not checked either
(``again``: checked when next asked for). Nothing about a check ever fails the save or the request that asked for
it.

The record, ``metrics["edits"]``: ``{"digest", "verdicts": {"floors+1": Verdict.to_dict(), ...}, "seconds"}`` where
it ran (a count the tree lacks or cannot change that way has no verdict), ``{"digest", "verdicts": None, "reason",
"again"}`` where it did not."""

from __future__ import annotations

import logging
import math
from time import perf_counter

from facaid.editing.check import SAMPLE, TRIES, check_edits
from facaid.editing.parameters import Parameter, named_parameters
from facaid.grammar.budget import WorkLimitError, reserve, seconds_left
from facaid.grammar.layout import count_expansion
from webapp.facades.parsing import parse_procedure

log = logging.getLogger(__name__)

KEY = "edits"  # where a procedure's metrics keep the record
COUNTS = {"floors": ("floor_height", "height", "width"), "bays": ("tile_width", "width", "height")}  # the counts
# judged: the length of the band an edit puts in, the side it grows along and the other side
CHECK_SECONDS = 1.0  # the most a check may be estimated to take at worst (`estimate`): past it, not checked
# what a check costs, measured on this project's 2-core machine (docs/site.md): per node instance of the tree (its
# four edited trees laid out, executed and flattened: 14 us a unit on trees of 6,000 to 58,000 units), per pixel (the
# label maps drawn and compared: 0.07 us) and per pixel compared in the search for the band's likeness (1 ns, at most
# `TRIES` places tried for each edit)
UNIT_SECONDS, PIXEL_SECONDS, COMPARE_SECONDS = 14e-6, 7e-8, 1e-9
CHECK_WORK = 14  # work units reserved per unit of the tree's (a unit of the budget is about a microsecond)
LEAVE = 0.5  # the share of a request's CPU time left that a check may be estimated to take: the rest is the request's
MINUS = "\u2212"


def current(metrics: dict | None, digest: str) -> dict | None:
    """The record of ``metrics`` when it judged the tree named ``digest`` (else None: there is none, or it is of
    another tree)."""
    found = (metrics or {}).get(KEY) if isinstance(metrics, dict) else None
    return found if isinstance(found, dict) and found.get("digest") == digest else None


def _band(params: dict[str, Parameter], name: str, side: float) -> float:
    """The length of the band ``name`` ± 1 puts in or takes out: the floor height (tile width), else the side over
    the count."""
    length = COUNTS[name][0]
    return params[length].value if length in params else side / max(1.0, params[name].value)


def estimate(tree, params: list[Parameter] | None = None) -> tuple[float, int]:
    """(seconds, units): what checking ``tree``'s edits would take at worst here, and its node instances. Without
    ``params`` (its named parameters), where the tree alone costs more than `CHECK_SECONDS`, that is the estimate:
    its named parameters are not read."""
    units = count_expansion(tree.root, tree.width, tree.height).instances
    seconds = UNIT_SECONDS * units + PIXEL_SECONDS * tree.width * tree.height
    if params is None and seconds > CHECK_SECONDS:
        return seconds, units
    params = {p.name: p for p in (named_parameters(tree) if params is None else params)}
    sides = {"width": tree.width, "height": tree.height}
    compared = 0.0
    sy, sx = SAMPLE
    for name, (_, along, across) in COUNTS.items():
        if name not in params or params[name].min == params[name].max:
            continue
        band, side, other = _band(params, name, sides[along]), sides[along], sides[across]
        # each of its two edits tries up to TRIES places, each against every band of the old facade
        compared += 2 * TRIES * math.ceil(band / sy) * math.ceil(other / sx) * max(1.0, side - band + 1)
    return seconds + COMPARE_SECONDS * compared, units


def _not_checked(digest: str, reason: str, again: bool = False) -> dict:
    return {"digest": digest, "verdicts": None, "reason": f"not checked: {reason}", "again": again}


def record(tree, digest: str) -> dict:
    """Check ``tree``'s edits (a parsed procedure, named ``digest``) and return the record; never raises."""
    try:
        seconds, units = estimate(tree)  # a tree too costly on its nodes and pixels alone: its parameters not read
        if seconds <= CHECK_SECONDS:
            params = named_parameters(tree)
            if not any(p.name in COUNTS and p.min < p.max for p in params):
                return {"digest": digest, "verdicts": {}, "seconds": 0.0}  # no count to change: nothing to judge
            seconds, units = estimate(tree, params)
        if seconds > CHECK_SECONDS:
            return _not_checked(digest, f"checking its edits would take more than the {CHECK_SECONDS:g} s a check "
                                        f"may take here (the facade is {tree.width:g} x {tree.height:g} px and lays "
                                        f"out {units:,} node instances)")
        left = seconds_left()
        if left is not None and seconds > LEAVE * left:
            return _not_checked(digest, f"the request had too little of its computing time left for the check (it "
                                        f"may take {seconds:.2f} s, and {left:.2f} s were left); it is checked when "
                                        "next asked for", True)
        try:
            reserve(CHECK_WORK * units)
        except WorkLimitError:
            return _not_checked(digest, f"the request had too little of its work budget left for the check (about "
                                        f"{CHECK_WORK * units:,} units); it is checked when next asked for", True)
        start = perf_counter()
        verdicts = check_edits(tree)
        return {"digest": digest, "verdicts": {k: _rounded(v.to_dict()) for k, v in verdicts.items()},
                "seconds": round(perf_counter() - start, 3)}
    except WorkLimitError:
        return _not_checked(digest, "the request ran out of its computing time during the check; it is checked when "
                                    "next asked for", True)
    except Exception as exc:  # a check is a figure about the tree: it never fails what saves or shows it
        log.exception("could not check the edits of tree %s", digest)
        return _not_checked(digest, f"the check failed ({type(exc).__name__}: {str(exc)[:200]})")


def _rounded(verdict: dict) -> dict:
    return {k: round(v, 4) if isinstance(v, float) else v for k, v in verdict.items()}


def checked(metrics: dict | None, data: dict, digest: str) -> dict:
    """``metrics`` with a record of the tree ``data`` (named ``digest``): the one it holds where that judged this tree
    and needs no second try, else a new one (`record`). A copy: the dict given is left as it is."""
    out = dict(metrics) if isinstance(metrics, dict) else {}
    kept = current(out, digest)
    if kept is not None and not kept.get("again"):
        return out
    try:
        tree = parse_procedure(data, sent=False)
    except Exception as exc:  # (a tree the site stored is valid; one that is not is said so, not raised)
        out[KEY] = _not_checked(digest, f"the tree could not be read ({str(exc)[:200]})")
        return out
    out[KEY] = record(tree, digest)
    return out


def for_tree(tree, digest: str, metrics: dict | None) -> dict:
    """The record of ``tree`` to show: the one kept in ``metrics`` when it judged this very tree (``digest``) and
    needs no second try, else one made now (not stored)."""
    kept = current(metrics, digest)
    return kept if kept is not None and not kept.get("again") else record(tree, digest)


def _said(name: str, key: str, verdict: dict) -> str:
    sign = "+" if key.endswith("+1") else MINUS
    return f"{name} {sign} 1 is {'clean' if verdict.get('clean') else 'not clean'}: {verdict.get('reason', '')}"


def judged(name: str, rec: dict | None) -> dict:
    """``{"checked", "check"}`` of the named parameter ``name`` by the record ``rec``: true where its + 1 and − 1
    (those that exist) are clean, false where one is not, null where no check applies (a length) or none ran; the
    words say why, and for a count what each edit did. A count judged has ``edits`` too: each edit (``"+1"``,
    ``"-1"``), whether it is clean and what was said of it."""
    if name not in COUNTS:
        return {"checked": None, "check": "not judged: only edits of the counts (floors, bays) are checked"}
    if rec is None:
        return {"checked": None, "check": "not checked: this tree has not been checked yet"}
    if rec.get("verdicts") is None:
        return {"checked": None, "check": rec.get("reason", "not checked")}
    mine = {k: v for k, v in rec["verdicts"].items() if k in (f"{name}+1", f"{name}-1")}
    if not mine:
        return {"checked": None, "check": f"no edit of {name} to judge: it cannot change here"}
    clean = all(v.get("clean") for v in mine.values())
    return {"checked": clean, "check": "; ".join(_said(name, k, v) for k, v in sorted(mine.items())),
            "edits": [{"edit": k[len(name):], "clean": bool(v.get("clean")), "said": _said(name, k, v)}
                      for k, v in sorted(mine.items())]}


def annotate(parameters: list[dict], rec: dict | None) -> list[dict]:
    """The named parameters (their dicts), each with ``checked`` and ``check`` (`judged`)."""
    return [{**p, **judged(p["name"], rec)} for p in parameters]


def unclean(rec: dict | None) -> dict[str, str]:
    """The counts whose edits did not pass (``checked`` false), each with the words of the edits that did not."""
    out = {}
    for name in COUNTS:
        said = judged(name, rec)
        if said["checked"] is False:
            out[name] = "; ".join(e["said"] for e in said["edits"] if not e["clean"])
    return out
