"""The simulated annotator (facaid.evaluation.assist) on every N-th CMP dev facade with its photo, knobs set as
NAME=VALUE (Python literals) on facaid.photo.repeats, facaid.completion: median and pooled effort, hit rate.

    .venv/bin/python experiments/2026-12-06-copies/sim.py 9 [REPEAT_MATCH="(2.0,0.8,0.6)"] [MATCH=0.6]
"""
import statistics
import sys

from facaid import completion
from facaid.completion import complete, copies
from facaid.evaluation.assist import simulate
from facaid.evaluation.real import load_records
from facaid.paths import DEFAULT_CMP
from facaid.photo import appearance, repeats

sys.path.insert(0, "experiments/2026-12-06-copies")
if any(a.startswith("FLOORS=") for a in sys.argv[2:]):
    import floors_proto
for kv in sys.argv[2:]:
    k, v = kv.split("=")
    if k == "FLOORS":
        continue
    if "floors_proto" in sys.modules and hasattr(sys.modules["floors_proto"], k):
        setattr(sys.modules["floors_proto"], k, __import__("ast").literal_eval(v))
        continue
    mod = repeats if hasattr(repeats, k) else (copies if hasattr(copies, k) else completion)
    import ast; setattr(mod, k, ast.literal_eval(v))
recs = load_records(DEFAULT_CMP, 189)[::int(sys.argv[1])]
eff = []; acc = rej = 0; act = els = 0
for rid, seg in recs:
    lv = appearance.levels(f"var/cmp_photos/{rid}.jpg", seg.width, seg.height)
    s = simulate(seg, lambda sg, rejected: complete(sg, lv, rejected=rejected))
    eff.append(s.effort); acc += s.accepted; rej += s.rejected; act += s.drawn + s.rejected; els += s.elements
    if False: print(rid, round(s.effort, 2), s.accepted, s.rejected, flush=True)
print(sys.argv[2:], "effort", round(statistics.median(eff), 3), "accepted", acc, "rejected", rej, "hit", round(acc / max(1, acc + rej), 2), "pooled", round(act / els, 3))
