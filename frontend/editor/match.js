// "Find similar": normalized cross-correlation of a drawn rectangle against the photo. No DOM: images are
// {width, height, data} with RGBA bytes (ImageData) or one float per pixel (gray).
import {intersects} from "./geometry.js";

export function toGray(image) {
  const {width, height, data} = image;
  const out = new Float32Array(width * height);
  for (let i = 0; i < out.length; i++) {
    out[i] = 0.299 * data[4 * i] + 0.587 * data[4 * i + 1] + 0.114 * data[4 * i + 2];
  }
  return {width, height, data: out};
}

/** Box-filter down by an integer factor. */
export function downsample(gray, factor) {
  if (factor <= 1) return gray;
  const w = Math.floor(gray.width / factor), h = Math.floor(gray.height / factor);
  const out = new Float32Array(w * h);
  for (let y = 0; y < h; y++) {
    for (let x = 0; x < w; x++) {
      let s = 0;
      for (let j = 0; j < factor; j++) {
        const row = (y * factor + j) * gray.width + x * factor;
        for (let i = 0; i < factor; i++) s += gray.data[row + i];
      }
      out[y * w + x] = s / (factor * factor);
    }
  }
  return {width: w, height: h, data: out};
}

function integrals(g) {
  const w = g.width + 1, h = g.height + 1;
  const s = new Float64Array(w * h), q = new Float64Array(w * h);
  for (let y = 1; y < h; y++) {
    let rs = 0, rq = 0;
    for (let x = 1; x < w; x++) {
      const v = g.data[(y - 1) * g.width + (x - 1)];
      rs += v; rq += v * v;
      s[y * w + x] = s[(y - 1) * w + x] + rs;
      q[y * w + x] = q[(y - 1) * w + x] + rq;
    }
  }
  return {s, q, w};
}

/**
 * Places where the photo looks like `box` (image pixels): [{x0, y0, x1, y1, score}], best first, not
 * overlapping each other, `box`, or any of `exclude`. Works on a copy scaled so the long side is <= maxSide.
 */
export function findSimilar(gray, box, {threshold = 0.8, maxResults = 100, exclude = [], maxSide = 480} = {}) {
  const factor = Math.max(1, Math.ceil(Math.max(gray.width, gray.height) / maxSide));
  const g = downsample(gray, factor);
  const tx0 = Math.round(box.x0 / factor), ty0 = Math.round(box.y0 / factor);
  const tw = Math.max(1, Math.round((box.x1 - box.x0) / factor)), th = Math.max(1, Math.round((box.y1 - box.y0) / factor));
  if (tw < 3 || th < 3 || tx0 + tw > g.width || ty0 + th > g.height) return [];
  const n = tw * th;
  const t = new Float32Array(n);
  let tm = 0;
  for (let j = 0; j < th; j++) for (let i = 0; i < tw; i++) { t[j * tw + i] = g.data[(ty0 + j) * g.width + tx0 + i]; tm += t[j * tw + i]; }
  tm /= n;
  let tn = 0;
  for (let k = 0; k < n; k++) { t[k] -= tm; tn += t[k] * t[k]; }
  tn = Math.sqrt(tn);
  if (tn < 1e-6) return [];  // a flat template matches everything
  const {s, q, w} = integrals(g);
  const scores = [];
  for (let y = 0; y + th <= g.height; y++) {
    for (let x = 0; x + tw <= g.width; x++) {
      const sum = s[(y + th) * w + x + tw] - s[y * w + x + tw] - s[(y + th) * w + x] + s[y * w + x];
      const sq = q[(y + th) * w + x + tw] - q[y * w + x + tw] - q[(y + th) * w + x] + q[y * w + x];
      const varw = sq - (sum * sum) / n;
      if (varw < 1e-6) continue;
      let dot = 0;
      for (let j = 0; j < th; j++) {
        const row = (y + j) * g.width + x;
        for (let i = 0; i < tw; i++) dot += t[j * tw + i] * g.data[row + i];
      }
      const score = dot / (tn * Math.sqrt(varw));
      if (score >= threshold) scores.push({x, y, score});
    }
  }
  scores.sort((a, b) => b.score - a.score);
  const taken = [box, ...exclude];
  const out = [];
  for (const c of scores) {
    const r = {x0: c.x * factor, y0: c.y * factor, x1: c.x * factor + (box.x1 - box.x0), y1: c.y * factor + (box.y1 - box.y0)};
    if (r.x1 > gray.width || r.y1 > gray.height) continue;
    if (taken.some((o) => intersects(o, r))) continue;
    out.push({...r, score: c.score});
    taken.push(r);
    if (out.length >= maxResults) break;
  }
  return out;
}

/**
 * Where the photo (`gray`) looks most like `box` within `radius` ({x, y}, image pixels) of `at` (a box of its
 * size): {x0, y0, x1, y1, score} (normalized cross-correlation), or null where no place of that size fits. Both are
 * compared at a scale where the box is at most `side` pixels across, so a search costs the same at any size.
 */
export function matchNear(gray, box, at, radius, {side = 40} = {}) {
  const w = box.x1 - box.x0, h = box.y1 - box.y0;
  const step = Math.max(1, Math.ceil(Math.max(w, h) / side));
  const template = patch(gray, box.x0, box.y0, w, h, step);
  if (!template) return null;
  const score = (t, x0, y0, every) => {
    const here = patch(gray, x0, y0, w, h, every);
    if (!here) return null;
    let dot = 0;
    for (let k = 0; k < here.v.length; k++) dot += t.v[k] * here.v[k];
    return {x0, y0, x1: x0 + w, y1: y0 + h, score: dot / (t.norm * here.norm)};
  };
  let best = null;
  for (let oy = -radius.y; oy <= radius.y; oy += step) {
    for (let ox = -radius.x; ox <= radius.x; ox += step) {
      const c = score(template, Math.round(at.x0 + ox), Math.round(at.y0 + oy), step);
      if (c && (!best || c.score > best.score)) best = c;
    }
  }
  if (!best || step === 1) return best;
  const whole = patch(gray, box.x0, box.y0, w, h, 1);  // to the pixel, every pixel, around the coarse best
  let fine = null;
  for (let oy = 1 - step; oy < step; oy++) {
    for (let ox = 1 - step; ox < step; ox++) {
      const c = score(whole, best.x0 + ox, best.y0 + oy, 1);
      if (c && (!fine || c.score > fine.score)) fine = c;
    }
  }
  return fine || best;
}

/** The gray levels of a w x h box at (x0, y0), every `step`-th pixel, less their mean, with their norm; null where
 * the box leaves the image or is flat. */
function patch(gray, x0, y0, w, h, step) {
  if (x0 < 0 || y0 < 0 || x0 + w > gray.width || y0 + h > gray.height) return null;
  const v = [];
  for (let y = y0; y < y0 + h; y += step) for (let x = x0; x < x0 + w; x += step) v.push(gray.data[y * gray.width + x]);
  const mean = v.reduce((s, a) => s + a, 0) / v.length;
  let norm = 0;
  for (let k = 0; k < v.length; k++) { v[k] -= mean; norm += v[k] * v[k]; }
  return norm < 1e-6 ? null : {v, norm: Math.sqrt(norm)};
}
