// Every change to a segmentation is a command with do(seg) and undo(seg). No DOM.
import {repeatRect, translate} from "./geometry.js";

/** Add rectangles ({label, x0, y0, x1, y1}); ids are assigned on the first do and kept for redo. */
export class AddRects {
  constructor(records, name = "add") { this.records = records.map((r) => ({...r})); this.name = name; }
  do(seg) { this.records = this.records.map((r) => seg.insert(r)); this.ids = this.records.map((r) => r.id); }
  undo(seg) { for (const id of this.ids) seg.remove(id); }
}

export class DeleteRects {
  constructor(ids) { this.ids = [...ids]; this.name = "delete"; }
  do(seg) { this.removed = this.ids.map((id) => seg.remove(id)); }
  undo(seg) { for (const r of this.removed) seg.insert(r); }
}

/** Change records: [{id, after: {fields}}]; the previous values are captured on do. */
export class UpdateRects {
  constructor(changes, name = "edit") { this.changes = changes.map((c) => ({id: c.id, after: {...c.after}})); this.name = name; }
  do(seg) {
    this.before = this.changes.map(({id}) => ({...seg.get(id)}));
    for (const {id, after} of this.changes) seg.update(id, after);
  }
  undo(seg) { for (const r of this.before) seg.update(r.id, r); }
}

export function moveRects(seg, ids, dx, dy) {
  return new UpdateRects(ids.map((id) => ({id, after: translate(seg.get(id), dx, dy)})), "move");
}

export function setLabel(ids, label) {
  return new UpdateRects(ids.map((id) => ({id, after: {label}})), "label");
}

export function duplicateRects(seg, ids, dx = 10, dy = 10) {
  return new AddRects(ids.map((id) => {
    const r = seg.get(id);
    return {label: r.label, ...translate(r, dx, dy)};
  }), "duplicate");
}

/** Copies of one rectangle on a row, column or grid (the original stays; copies outside the image are cut). */
export function repeatRects(seg, id, options) {
  const r = seg.get(id);
  const copies = repeatRect(r, options).slice(1)
    .filter((c) => c.x0 < seg.width && c.y0 < seg.height && c.x1 > 0 && c.y1 > 0)
    .map((c) => ({label: r.label, ...c}));
  return new AddRects(copies, "repeat");
}

/** Several commands as one step (a split: the rectangle deleted and its pieces added); undone in reverse. */
export class Batch {
  constructor(commands, name) { this.commands = commands; this.name = name; }
  do(seg) { for (const c of this.commands) c.do(seg); }
  undo(seg) { for (const c of [...this.commands].reverse()) c.undo(seg); }
  /** The ids its AddRects gave, once done. */
  get ids() { return this.commands.flatMap((c) => (c instanceof AddRects ? c.ids || [] : [])); }
}

/** Replace everything (import of a segmentation JSON). */
export class ReplaceAll {
  constructor(records) { this.records = records.map((r) => ({...r})); this.name = "import"; }
  do(seg) {
    this.before = [...seg.rects.values()];
    for (const r of this.before) seg.remove(r.id);
    this.ids = this.records.map((r) => seg.insert({label: r.label, x0: r.x0, y0: r.y0, x1: r.x1, y1: r.y1}).id);
  }
  undo(seg) {
    for (const id of this.ids) seg.remove(id);
    for (const r of this.before) seg.insert(r);
  }
}
