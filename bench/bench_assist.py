"""Assisted segmentation on the CMP annotations: how much drawing completion saves (issue 43's benchmark).

    .venv/bin/python bench/bench_assist.py [--stride 1] [--limit N] [--min-score S] [--json F]
    .venv/bin/python bench/bench_assist.py --generated 12      # + photo-like renders of generated facades
    .venv/bin/python bench/bench_assist.py --timing 6          # one call's time, with and without the photo
    .venv/bin/python bench/bench_assist.py --photos var/cmp_photos --stride 9   # + CMP's own photos (git-ignored)

A simulated annotator (`facaid.evaluation.assist.simulate`) draws each facade's true elements in reading order,
asks `facaid.completion.complete` for proposals after every third, accepts at no cost each proposal that matches
a true element not drawn yet (same class, IoU >= 0.7) and pays one action for every other one, and stops at
95 % pixel accuracy. Effort = actions / elements (1.0: drawing everything). Printed for the dev half (facades
1-189) and the test half (190-378) apart, beside the effort without completion (the 95 % stop alone), with the
median time of a completion call. CMP is evaluation data: nothing here trains. CMP's photos are not in the repo:
``--generated N`` runs the same annotator on N held-out generated facades (seeds 5000 on) drawn on photo-like
renders of themselves (`facaid.photo.photolike.render_photo`), their wall one rectangle as a person draws it
(`facaid.evaluation.assist.as_drawn`), not the flattened pieces around each element, without and with the photo
(searched, and checking the proposals). ``--photos DIR`` gives the CMP annotations their own photos
(``DIR/cmp_bNNNN.jpg``, read out of a public copy of the CMP base set into a git-ignored cache, issue 57: never in the
repo); only the facades whose photo is there are run, each without and with its photo. The hit rate is accepted ÷
proposed (accepted + rejected).
"""

from __future__ import annotations

import argparse
import functools
import json
import statistics
import time
from pathlib import Path

from facaid.completion import complete
from facaid.defaults import DEFAULT_MIN_SCORE
from facaid.evaluation.assist import as_drawn, simulate, summary
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.paths import DEFAULT_CMP


def hits(s: dict) -> float:
    """Accepted ÷ proposed: a proposer that floods the person with wrong boxes is seen here."""
    return s["accepted"] / max(1, s["accepted"] + s["rejected"])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=str(DEFAULT_CMP))
    ap.add_argument("--stride", type=int, default=1, help="every N-th facade of each half")
    ap.add_argument("--limit", type=int, default=None, help="at most N facades of each half")
    ap.add_argument("--min-score", type=float, default=DEFAULT_MIN_SCORE)
    ap.add_argument("--json", default=None)
    ap.add_argument("--generated", type=int, default=0, help="N generated facades with photo-like renders instead")
    ap.add_argument("--photos", default=None, help="a folder of CMP's photos, cmp_bNNNN.jpg (a git-ignored cache)")
    ap.add_argument("--timing", type=int, default=0,
                    help="time one call on 150 drawn elements of N generated facades rendered at 2x (1-2 MP photos)")
    args = ap.parse_args()
    if args.generated:
        return generated(args)
    if args.timing:
        return timing(args)
    records = load_records(args.data)
    halves = {"dev": records[:DEV_FACADES], "test": records[DEV_FACADES:]}
    calls: list[float] = []

    def timed(seg, **kw):
        t0 = time.perf_counter()
        out = complete(seg, min_score=args.min_score, **kw)
        calls.append(time.perf_counter() - t0)
        return out

    photo_calls: list[float] = []

    def timed_photo(seg, photo, **kw):
        t0 = time.perf_counter()
        out = complete(seg, photo, min_score=args.min_score, **kw)
        photo_calls.append(time.perf_counter() - t0)
        return out

    photos = Path(args.photos) if args.photos else None
    result = {"min_score": args.min_score}
    for name, recs in halves.items():
        recs = recs[:: args.stride][: args.limit]
        if photos is not None:
            recs = [(rid, seg) for rid, seg in recs if (photos / f"{rid}.jpg").exists()]
        if not recs:
            continue
        assisted = [simulate(seg, timed) for _, seg in recs]
        alone = [simulate(seg, functools.partial(lambda s, rejected: [])) for _, seg in recs]
        result[name] = {"assisted": summary(assisted), "unassisted": summary(alone)}
        if photos is not None:
            result[name]["photo"] = summary([
                simulate(seg, functools.partial(timed_photo, photo=str(photos / f"{rid}.jpg"))) for rid, seg in recs])
        a, u = result[name]["assisted"], result[name]["unassisted"]
        print(f"{name}: {a['facades']} facades, median effort {a['effort_median']:.3f} with completion "
              f"({a['accepted']} proposals accepted, {a['rejected']} rejected, hit rate {hits(a):.2f}, {a['drawn']} "
              f"drawn of {a['elements']}), {u['effort_median']:.3f} without")
        if photos is not None:
            p = result[name]["photo"]
            print(f"{name}, with its photo: median effort {p['effort_median']:.3f} ({p['accepted']} accepted, "
                  f"{p['rejected']} rejected, hit rate {hits(p):.2f}, {p['drawn']} drawn)")
    for key, took in (("call_seconds", calls), ("photo_call_seconds", photo_calls)):
        if took:
            result[f"{key}_median"] = statistics.median(took)
            result[f"{key}_p90"] = sorted(took)[int(0.9 * (len(took) - 1))]
            print(f"completion call{' with the photo' if 'photo' in key else ''}: median "
                  f"{1000 * statistics.median(took):.1f} ms, p90 {1000 * result[f'{key}_p90']:.1f} ms "
                  f"({len(took)} calls)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


def timing(args) -> None:
    """The median time of one completion call with and without the photo on the first 150 elements (reading
    order) of N held-out generated facades, each scaled 2x with its photo-like render (0.8-2.2 MP), 5 calls each."""
    from PIL import Image

    from facaid.generator import generate
    from facaid.photo.photolike import render_photo
    from facaid.segmentation import Rect, Segmentation

    took: dict[str, list[float]] = {"structure": [], "photo": []}
    for seed in range(5000, 5000 + args.timing):
        seg = as_drawn(generate(seed).segmentation)
        big = Segmentation(2 * seg.width, 2 * seg.height, tuple(
            Rect(r.label, 2 * r.x0, 2 * r.y0, 2 * r.x1, 2 * r.y1) for r in seg.rects))
        photo = render_photo(generate(seed).segmentation, seed).resize((big.width, big.height), Image.BILINEAR)
        drawn = Segmentation(big.width, big.height, tuple(sorted(big.rects, key=lambda r: (r.y0, r.x0))[:150]))
        for name, kw in (("structure", {}), ("photo", {"photo": photo})):
            runs = []
            for _ in range(5):
                t0 = time.perf_counter()
                complete(drawn, min_score=args.min_score, **kw)
                runs.append(time.perf_counter() - t0)
            took[name].append(statistics.median(runs))
    for name, t in took.items():
        print(f"150 drawn elements, 0.8-2.2 MP ({len(t)} facades), {name}: median "
              f"{1000 * statistics.median(t):.0f} ms, at most {1000 * max(t):.0f} ms")


def generated(args) -> None:
    from facaid.generator import generate
    from facaid.photo.photolike import render_photo

    cases = [(as_drawn(g.segmentation), render_photo(g.segmentation, seed))
             for seed in range(5000, 5000 + args.generated) for g in [generate(seed)]]
    result = {"min_score": args.min_score, "facades": len(cases)}
    for name, propose in (("alone", lambda seg, photo: (lambda s, rejected: [])),
                          ("structure", lambda seg, photo: functools.partial(complete, min_score=args.min_score)),
                          ("photo", lambda seg, photo: functools.partial(complete, photo=photo,
                                                                         min_score=args.min_score))):
        calls: list[float] = []

        def timed(s, _p=None, _calls=calls, **kw):
            t0 = time.perf_counter()
            out = _p(s, **kw)
            _calls.append(time.perf_counter() - t0)
            return out

        sessions = [simulate(seg, functools.partial(timed, _p=propose(seg, photo))) for seg, photo in cases]
        result[name] = summary(sessions) | {"call_seconds_median": statistics.median(calls) if calls else None}
        s = result[name]
        ms = f", {1000 * s['call_seconds_median']:.1f} ms a call" if name != "alone" else ""
        print(f"generated, {name}: median effort {s['effort_median']:.3f} ({s['accepted']} accepted, "
              f"{s['rejected']} rejected, {s['drawn']} drawn of {s['elements']}){ms}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
