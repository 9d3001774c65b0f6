"""What the site's check of a procedure's edits costs (issue 67, item 4): the check itself on CMP's editable
readings, its estimate against its time, and what it adds to a save.

    .venv/bin/python bench/bench_edit_checks.py [--start 0] [--limit 60] [--saves 15]

1. ``webapp.facades.editcheck.record`` of the editable reading (`facaid.reading.lattice.read_lattice`) of CMP facades
   ``--start`` to ``--start + --limit``: seconds (median, 90th percentile, most), how many were not checked (their
   estimate past `CHECK_SECONDS`), the estimate over the time it took (at least 1 is an upper bound), and on how
   many the self-check agrees with the rule applied offline (`facaid.editing.check.check_edits`: the same verdict
   on floors + 1 and bays + 1; a tree not checked disagrees).
2. A save through the API (``PATCH procedures/<code>/`` with a new tree: two trees in turn, so each save is a new
   version whose edits are checked) on a scratch SQLite database, in this process, with the check and without it
   (`CHECK_SECONDS` 0: the estimate alone), for a generated facade and the CMP reading whose check took the median
   time of those with all four edits judged: median of ``--saves`` each, and the difference.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def readings(start: int, limit: int) -> list:
    from facaid.paths import DEFAULT_CMP
    from facaid.reading.lattice import read_lattice
    from facaid.segmentation import Segmentation

    out = []
    with open(DEFAULT_CMP) as f:
        lines = f.read().splitlines()[start:start + limit]
    for line in lines:
        obj = json.loads(line)
        tree = read_lattice(Segmentation.from_dict({k: obj[k] for k in ("width", "height", "rects")}, clip=True))
        if tree is not None:
            out.append((obj["id"], tree))
    return out


def the_check(trees: list) -> tuple:
    """Times the check of each tree; returns the (name, tree) whose check took the median time of those with every
    edit judged (four verdicts)."""
    from facaid.editing.check import MORE, check_edits
    from webapp.facades import editcheck

    times, ratios, refused, judged, agree = [], [], 0, [], 0
    for name, tree in trees:
        estimate, _ = editcheck.estimate(tree)
        start = time.perf_counter()
        rec = editcheck.record(tree, "bench")
        took = time.perf_counter() - start
        # the self-check agrees with the rule where it gives floors + 1 and bays + 1 the rule's verdicts
        rule = {key: v.clean for key, v in check_edits(tree, MORE).items()}
        mine = {key: v["clean"] for key, v in (rec["verdicts"] or {}).items() if key in rule}
        agree += mine == rule
        if rec["verdicts"] is None:
            refused += 1
            continue
        times.append(took)
        ratios.append(estimate / took)
        if len(rec["verdicts"]) == 4:
            judged.append((took, name, tree))
    times.sort()
    print(f"the check, {len(trees)} CMP readings: median {statistics.median(times):.3f} s, 90th percentile "
          f"{times[int(0.9 * (len(times) - 1))]:.3f} s, most {times[-1]:.3f} s; not checked (estimate past "
          f"{editcheck.CHECK_SECONDS:g} s): {refused}; estimate / time: least {min(ratios):.2f}, median "
          f"{statistics.median(ratios):.2f}; every edit judged on {len(judged)}; the self-check agrees with the "
          f"rule (floors + 1, bays + 1) on {agree} of {len(trees)} ({100 * agree / len(trees):.1f} %)")
    judged.sort(key=lambda t: t[0])
    _, name, tree = judged[len(judged) // 2]
    return name, tree


def saves(trees: dict, repeat: int) -> None:
    import django

    django.setup()
    from django.contrib.auth import get_user_model
    from django.core.management import call_command
    from rest_framework.test import APIClient

    from facaid.editing.parameters import named_parameters, set_parameter
    from webapp.facades import editcheck
    from webapp.facades.models import Procedure

    call_command("migrate", verbosity=0)
    user = get_user_model().objects.create_user("bench", "b@example.com", "bench-password-1")
    client = APIClient()
    client.force_login(user)
    limit_then = editcheck.CHECK_SECONDS
    for name, tree in trees.items():
        floors = {p.name: p for p in named_parameters(tree)}["floors"]
        pair = [tree.to_dict(), set_parameter(tree, "floors", floors.value + 1).to_dict()]
        proc = Procedure.objects.create(owner=user, data=pair[0])
        figures = {}
        for label, limit in (("with the check", limit_then), ("without", 0.0)):
            editcheck.CHECK_SECONDS = limit
            times = []
            for i in range(repeat + 1):
                start = time.perf_counter()
                r = client.patch(f"/api/v1/procedures/{proc.code}/", {"data": pair[(i + 1) % 2]}, format="json")
                took = time.perf_counter() - start
                assert r.status_code == 200, r.content
                checked = r.json()["metrics"]["edits"]["verdicts"] is not None
                assert checked == (limit > 0), r.json()["metrics"]["edits"]
                if i:  # the first one warms up
                    times.append(took)
            figures[label] = statistics.median(times)
        editcheck.CHECK_SECONDS = limit_then
        print(f"a save of {name} ({tree.width:g} x {tree.height:g} px): {figures['with the check']:.3f} s with the "
              f"check, {figures['without']:.3f} s without: the check adds "
              f"{figures['with the check'] - figures['without']:.3f} s (median of {repeat})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--limit", type=int, default=60)
    ap.add_argument("--saves", type=int, default=15)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="facaid-checks-")
    os.environ.update(DJANGO_SETTINGS_MODULE="webapp.settings", FACAID_VAR=tmp, MEDIA_ROOT=str(Path(tmp) / "media"),
                      DATABASE_URL=f"sqlite:///{Path(tmp) / 'db.sqlite3'}", SECRET_KEY="bench-" * 10, DEBUG="0",
                      FACAID_HTTPS="0", FACAID_API_USER_RATE="none", FACAID_API_HEAVY_RATE="none")
    from facaid.generator import generate

    name, median = the_check(readings(args.start, args.limit))
    saves({"a generated facade": generate(3).procedure, f"CMP {name}'s reading (the median check)": median},
          args.saves)


if __name__ == "__main__":
    main()
