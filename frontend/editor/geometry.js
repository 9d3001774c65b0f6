// Rectangles in image pixels: {x0, y0, x1, y1}, half-open, origin top-left. No DOM.

export function normalize(r) {
  return {x0: Math.min(r.x0, r.x1), y0: Math.min(r.y0, r.y1), x1: Math.max(r.x0, r.x1), y1: Math.max(r.y0, r.y1)};
}

/** Round to whole pixels and clip to the image; null when nothing of at least 1x1 is left. */
export function clampToImage(r, width, height) {
  const n = normalize(r);
  const x0 = Math.max(0, Math.min(width, Math.round(n.x0)));
  const y0 = Math.max(0, Math.min(height, Math.round(n.y0)));
  const x1 = Math.max(0, Math.min(width, Math.round(n.x1)));
  const y1 = Math.max(0, Math.min(height, Math.round(n.y1)));
  return x1 - x0 >= 1 && y1 - y0 >= 1 ? {x0, y0, x1, y1} : null;
}

export function contains(r, x, y) {
  return x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1;
}

export function intersects(a, b) {
  return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}

/** Rectangles drawn twice: for each box and class that more than one rectangle has, {label, count}. */
export function identical(rects) {
  const seen = new Map();
  for (const r of rects) {
    const key = `${r.label} ${r.x0} ${r.y0} ${r.x1} ${r.y1}`;
    seen.set(key, {label: r.label, count: (seen.get(key)?.count || 0) + 1});
  }
  return [...seen.values()].filter((v) => v.count > 1);
}

export function translate(r, dx, dy) {
  return {x0: r.x0 + dx, y0: r.y0 + dy, x1: r.x1 + dx, y1: r.y1 + dy};
}

/** Move by (dx, dy) but keep the rectangle inside the image, size unchanged. */
export function moveWithin(r, dx, dy, width, height) {
  const w = r.x1 - r.x0, h = r.y1 - r.y0;
  const x0 = Math.max(0, Math.min(width - w, r.x0 + dx));
  const y0 = Math.max(0, Math.min(height - h, r.y0 + dy));
  return {x0, y0, x1: x0 + w, y1: y0 + h};
}

export const HANDLES = ["nw", "n", "ne", "e", "se", "s", "sw", "w"];

/** The rectangle with the edges named by a handle ("nw", "e", ...) moved to (x, y), not normalized: a handle
 * dragged across the opposite edge keeps its name (x0 may pass x1), so that snapping moves the dragged edge. */
export function dragEdges(r, handle, x, y) {
  const out = {...r};
  if (handle.includes("n")) out.y0 = y;
  if (handle.includes("s")) out.y1 = y;
  if (handle.includes("w")) out.x0 = x;
  if (handle.includes("e")) out.x1 = x;
  return out;
}

/** The rectangle with the edges named by a handle moved to (x, y). */
export const resize = (r, handle, x, y) => normalize(dragEdges(r, handle, x, y));

/** Handle positions of a rectangle: {name: [x, y]}. */
export function handlePoints(r) {
  const mx = (r.x0 + r.x1) / 2, my = (r.y0 + r.y1) / 2;
  return {nw: [r.x0, r.y0], n: [mx, r.y0], ne: [r.x1, r.y0], e: [r.x1, my], se: [r.x1, r.y1], s: [mx, r.y1],
    sw: [r.x0, r.y1], w: [r.x0, my]};
}

/** The handle within `tolerance` (image pixels) of (x, y), or null. */
export function handleAt(r, x, y, tolerance) {
  for (const [name, [hx, hy]] of Object.entries(handlePoints(r))) {
    if (Math.abs(hx - x) <= tolerance && Math.abs(hy - y) <= tolerance) return name;
  }
  return null;
}

/**
 * Snap the moving edges of `r` to the edges of `others` (and the image border) within `threshold` pixels.
 * `edges` names the edges that move ("x0", "x1", "y0", "y1"); when both edges of an axis move (a drag), the
 * rectangle keeps its size. Returns {rect, guides}: guides are {axis: "x"|"y", at} lines to draw.
 */
export function snap(r, others, threshold, edges = ["x0", "x1", "y0", "y1"], bounds = null) {
  const xs = [], ys = [];
  for (const o of others) { xs.push(o.x0, o.x1); ys.push(o.y0, o.y1); }
  if (bounds) { xs.push(0, bounds.width); ys.push(0, bounds.height); }
  const out = {...r};
  const guides = [];
  for (const [axis, lo, hi, targets] of [["x", "x0", "x1", xs], ["y", "y0", "y1", ys]]) {
    const moving = [lo, hi].filter((e) => edges.includes(e));
    let best = null;
    for (const e of moving) {
      for (const t of targets) {
        const d = t - r[e];
        if (Math.abs(d) <= threshold && (best === null || Math.abs(d) < Math.abs(best.d))) best = {d, at: t};
      }
    }
    if (best === null) continue;
    if (moving.length === 2) { out[lo] += best.d; out[hi] += best.d; } else { out[moving[0]] += best.d; }
    guides.push({axis, at: best.at});
  }
  return {rect: out, guides};
}

/** Copies of `r` along a row, a column or on a grid: `cols` x `rows` with steps dx, dy (the original first). */
export function repeatRect(r, {cols = 1, rows = 1, dx = 0, dy = 0}) {
  if (!(Number.isInteger(cols) && Number.isInteger(rows) && cols >= 1 && rows >= 1)) {
    throw new Error("counts must be whole numbers of at least 1");
  }
  if (cols * rows > 2000) throw new Error("at most 2000 copies at once");
  const out = [];
  for (let j = 0; j < rows; j++) {
    for (let i = 0; i < cols; i++) out.push(translate(r, i * dx, j * dy));
  }
  return out;
}

/** The 3x3 homography (row-major array of 9) mapping four points src[i] -> dst[i]. */
export function homography(src, dst) {
  const a = [], b = [];
  for (let i = 0; i < 4; i++) {
    const [x, y] = src[i], [u, v] = dst[i];
    a.push([x, y, 1, 0, 0, 0, -u * x, -u * y]);
    a.push([0, 0, 0, x, y, 1, -v * x, -v * y]);
    b.push(u, v);
  }
  // Gaussian elimination with partial pivoting on the 8x8 system
  const n = 8;
  for (let c = 0; c < n; c++) {
    let p = c;
    for (let r = c + 1; r < n; r++) if (Math.abs(a[r][c]) > Math.abs(a[p][c])) p = r;
    if (Math.abs(a[p][c]) < 1e-12) throw new Error("the four points do not define a homography");
    [a[c], a[p]] = [a[p], a[c]];
    [b[c], b[p]] = [b[p], b[c]];
    for (let r = 0; r < n; r++) {
      if (r === c) continue;
      const f = a[r][c] / a[c][c];
      for (let k = c; k < n; k++) a[r][k] -= f * a[c][k];
      b[r] -= f * b[c];
    }
  }
  return [...b.map((v, i) => v / a[i][i]), 1];
}

export function applyHomography(h, x, y) {
  const w = h[6] * x + h[7] * y + h[8];
  return [(h[0] * x + h[1] * y + h[2]) / w, (h[3] * x + h[4] * y + h[5]) / w];
}

/** Width and height of the rectified image: the mean lengths of opposite edges (as facaid/photo/rectify.py). */
export function rectifiedSize(corners) {
  const d = (p, q) => Math.hypot(p[0] - q[0], p[1] - q[1]);
  const [tl, tr, br, bl] = corners;
  return [Math.max(1, Math.round((d(tl, tr) + d(bl, br)) / 2)), Math.max(1, Math.round((d(tl, bl) + d(tr, br)) / 2))];
}

/** Is the quadrilateral (TL, TR, BR, BL) convex and in order? */
export function isConvexQuad(corners) {
  let sign = 0;
  for (let i = 0; i < 4; i++) {
    const [a, b, c] = [corners[i], corners[(i + 1) % 4], corners[(i + 2) % 4]];
    const cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]);
    if (Math.abs(cross) < 1e-9) return false;
    if (sign === 0) sign = Math.sign(cross);
    else if (Math.sign(cross) !== sign) return false;
  }
  return true;
}

/** Rectangles of the original photo carried into its rectified image: the quadrilateral `corners` (TL, TR, BR,
 * BL in the original) is the rectified image of `width` x `height`; each box's four corners go through that
 * homography and the box becomes the axis-aligned one around them, cut to the image. A box that keeps less than
 * half of itself inside (outside the facade) is left out. {rects, left: how many were left out}. */
export function throughRectification(rects, corners, width, height) {
  const h = homography(corners, [[0, 0], [width, 0], [width, height], [0, height]]);
  const out = [];
  let left = 0;
  for (const r of rects) {
    const pts = [[r.x0, r.y0], [r.x1, r.y0], [r.x1, r.y1], [r.x0, r.y1]].map(([x, y]) => applyHomography(h, x, y));
    const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
    const box = {x0: Math.min(...xs), y0: Math.min(...ys), x1: Math.max(...xs), y1: Math.max(...ys)};
    const cut = {x0: Math.max(0, Math.round(box.x0)), y0: Math.max(0, Math.round(box.y0)),
      x1: Math.min(width, Math.round(box.x1)), y1: Math.min(height, Math.round(box.y1))};
    const whole = (box.x1 - box.x0) * (box.y1 - box.y0), kept = (cut.x1 - cut.x0) * (cut.y1 - cut.y0);
    if (!xs.concat(ys).every(Number.isFinite) || cut.x1 - cut.x0 < 1 || cut.y1 - cut.y0 < 1 || kept < whole / 2) {
      left++;
    } else {
      out.push({label: r.label, ...cut});
    }
  }
  return {rects: out, left};
}
