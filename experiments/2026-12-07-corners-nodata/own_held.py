"""How much no data each proposal of a `bench/bench_corners.py --json` file holds by the proposal's own mask (at the
work size, from the photo re-encoded as the bench gives it), over 0.5 %.

    .venv/bin/python experiments/2026-12-07-corners-nodata/own_held.py CORNERS.json var/cmp_photos
"""
import json, sys
import numpy as np
from PIL import Image
from facaid.photo.nodata import nodata_mask, held
from facaid.photo.corners import _work_channels, _nearest_luma
rows = json.load(open(sys.argv[1])); d = sys.argv[2]; over = []
for r in rows:
    import io
    im = Image.open(f"{d}/{r['id']}.jpg").convert("RGB"); buf = io.BytesIO(); im.save(buf, "JPEG", quality=92); buf.seek(0)
    im = Image.open(buf).convert("RGB")
    ch = _work_channels(im); gh, gw = ch[0].shape
    m = nodata_mask(_nearest_luma(im, (gw, gh), ch[0]))
    pts = np.array(r["corners"]) * np.array([gw / im.width, gh / im.height])
    h = held(pts, m)
    if h > 0.005: over.append((r["id"], round(h, 4)))
print(len(rows), "over 0.5 % by the proposal's own mask:", over)
