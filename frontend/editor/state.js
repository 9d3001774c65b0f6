// The segmentation being edited: plain records {id, label, x0, y0, x1, y1}. No DOM.
import {clampToImage, normalize} from "./geometry.js";
import {LABELS, priority} from "./labels.js";

export class SegmentationError extends Error {}

const MAX_SIDE = 100000;
const MAX_RECTS = 20000;

export class Segmentation {
  constructor(width, height) {
    if (!(Number.isInteger(width) && Number.isInteger(height) && width > 0 && height > 0 && width <= MAX_SIDE &&
          height <= MAX_SIDE)) {
      throw new SegmentationError(`width and height must be whole numbers in 1..${MAX_SIDE}, got ${width}x${height}`);
    }
    this.width = width;
    this.height = height;
    this.rects = new Map();  // id -> record, in insertion order
    this.nextId = 1;
  }

  get size() { return this.rects.size; }

  get(id) {
    const r = this.rects.get(id);
    if (!r) throw new Error(`no rectangle ${id}`);
    return r;
  }

  /** Insert a record (with its id when it has one, as undo does); returns the stored record. */
  insert(record) {
    if (!LABELS.includes(record.label)) throw new SegmentationError(`unknown label ${JSON.stringify(record.label)}`);
    const box = clampToImage(record, this.width, this.height);
    if (!box) throw new SegmentationError("a rectangle must cover at least one pixel of the image");
    const id = record.id ?? this.nextId;
    this.nextId = Math.max(this.nextId, id + 1);
    const stored = {id, label: record.label, ...box};
    this.rects.set(id, stored);
    return stored;
  }

  remove(id) {
    const r = this.get(id);
    this.rects.delete(id);
    return r;
  }

  /** Replace fields of a record (label and/or box); the box is clamped to the image. */
  update(id, fields) {
    const r = this.get(id);
    const next = {...r, ...fields};
    const box = clampToImage(next, this.width, this.height);
    if (!box) throw new SegmentationError("a rectangle must cover at least one pixel of the image");
    if (!LABELS.includes(next.label)) throw new SegmentationError(`unknown label ${JSON.stringify(next.label)}`);
    const stored = {id, label: next.label, ...box};
    this.rects.set(id, stored);
    return stored;
  }

  /** Records bottom to top in the paint order (facade under windows under balconies ...), then by id. */
  paintOrder() {
    return [...this.rects.values()].sort((a, b) => priority(a.label) - priority(b.label) || a.id - b.id);
  }

  /** The topmost record at (x, y) in the paint order among those `accept` takes, or null. */
  topAt(x, y, accept = () => true) {
    const order = this.paintOrder();
    for (let i = order.length - 1; i >= 0; i--) {
      const r = order[i];
      if (x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1 && accept(r)) return r;
    }
    return null;
  }

  /** The segmentation JSON contract. */
  toJSON() {
    return {width: this.width, height: this.height,
      rects: this.paintOrder().map(({label, x0, y0, x1, y1}) => ({label, x0, y0, x1, y1}))};
  }

  static fromJSON(obj) {
    if (obj === null || typeof obj !== "object" || Array.isArray(obj)) {
      throw new SegmentationError("a segmentation must be a JSON object with width, height and rects");
    }
    const seg = new Segmentation(obj.width, obj.height);
    if (!Array.isArray(obj.rects)) throw new SegmentationError("rects must be a list");
    if (obj.rects.length > MAX_RECTS) throw new SegmentationError(`at most ${MAX_RECTS} rectangles`);
    obj.rects.forEach((r, i) => {
      for (const k of ["x0", "y0", "x1", "y1"]) {
        if (typeof r?.[k] !== "number" || !Number.isFinite(r[k])) {
          throw new SegmentationError(`rects[${i}].${k} must be a number`);
        }
      }
      const n = normalize(r);
      if (n.x0 < 0 || n.y0 < 0 || n.x1 > seg.width || n.y1 > seg.height) {
        throw new SegmentationError(`rects[${i}] reaches outside the ${seg.width}x${seg.height} image`);
      }
      try {
        seg.insert({label: r.label, ...n});
      } catch (err) {
        throw new SegmentationError(`rects[${i}]: ${err.message}`);
      }
    });
    return seg;
  }
}
