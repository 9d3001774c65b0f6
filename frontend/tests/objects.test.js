// Hiding and locking classes: what the tools may still pick, draw and snap to; never a change to the segmentation.
import assert from "node:assert/strict";
import {test} from "node:test";

import {AddRects} from "../editor/commands.js";
import {History} from "../editor/history.js";
import {freeView, layersNote, noFacadeNote, objectGroups, pickable, pickableSelection, shown, toggleLayer}
  from "../editor/objects.js";
import {Segmentation} from "../editor/state.js";
import {press} from "../editor/tools/select.js";

function scene() {
  const seg = new Segmentation(200, 100);
  const history = new History(seg);
  history.execute(new AddRects([{label: "facade", x0: 0, y0: 0, x1: 200, y1: 100},
    {label: "window", x0: 20, y0: 20, x1: 40, y1: 50}, {label: "window", x0: 60, y0: 20, x1: 80, y1: 50},
    {label: "door", x0: 100, y0: 60, x1: 120, y1: 100}]));
  return {seg, history};
}
const at = (x, y, mods = {}) => ({x, y, sx: x, sy: y, shift: false, alt: false, ...mods});
const context = (seg, layers, extra = {}) => ({seg, selection: new Set(), label: "door", scale: 1, snap: true, layers,
  ...extra});

test("object list: groups by class in the palette's order with counts and their flags", () => {
  const {seg} = scene();
  const layers = toggleLayer(freeView(), "locked", "window");
  const groups = objectGroups(seg, layers);
  assert.deepEqual(groups.map((g) => [g.label, g.count, g.hidden, g.locked]),
    [["facade", 1, false, false], ["window", 2, false, true], ["door", 1, false, false]]);
  assert.deepEqual(groups[1].rects.map((r) => r.id), [2, 3]);
});

test("hide and lock: toggled back, named in a note, never touching the segmentation or its history", () => {
  const {seg, history} = scene();
  const before = JSON.stringify(seg.toJSON());
  let layers = toggleLayer(freeView(), "hidden", "window");
  layers = toggleLayer(layers, "locked", "facade");
  assert.equal(layersNote(layers), "hidden: window; locked: facade");
  assert.ok(!shown(layers, seg.get(2)) && !pickable(layers, seg.get(2)));
  assert.ok(shown(layers, seg.get(1)) && !pickable(layers, seg.get(1)));
  assert.equal(layersNote(toggleLayer(toggleLayer(layers, "hidden", "window"), "locked", "facade")), "");
  assert.equal(JSON.stringify(seg.toJSON()), before);
  assert.equal(history.done.length, 1);
  assert.throws(() => toggleLayer(layers, "hidden", "tree"), /unknown label/);
});

test("hide and lock: a press passes through them to what lies below; the marquee leaves them out", () => {
  const {seg} = scene();
  const locked = toggleLayer(freeView(), "locked", "window");
  const p = press("select", at(30, 30), context(seg, locked), {});
  assert.equal(p.gesture.kind, "marquee");  // the wall under the locked window: a box, or a click that selects it
  assert.deepEqual([...p.gesture.up(context(seg, locked, {selection: p.selection})).selection], [1]);
  const both = toggleLayer(toggleLayer(freeView(), "hidden", "window"), "locked", "facade");
  const q = press("select", at(30, 30), context(seg, both), {});
  assert.equal(q.gesture.kind, "marquee");  // nothing to pick there: a box instead
  q.gesture.move(at(130, 90));
  assert.deepEqual([...q.gesture.up(context(seg, both)).selection], [4]);  // the door, not the hidden windows
  const wall = toggleLayer(freeView(), "locked", "facade");  // the windows shown and free again: caught
  const free = press("select", at(5, 5), context(seg, wall), {}).gesture;
  free.move(at(130, 90));
  assert.deepEqual([...free.up(context(seg, wall)).selection].sort(), [2, 3, 4]);
});

test("hide: nothing snaps to a hidden class's edges; a locked class's edges still draw lines to snap to", () => {
  const {seg} = scene();
  const drawTo = (layers) => {
    const g = press("draw", at(140, 10), context(seg, layers), {}).gesture;
    g.move(at(170, 47), context(seg, layers));  // 3 px above the windows' bottom edge at y = 50
    return g.rect.y1;
  };
  assert.equal(drawTo(freeView()), 50);
  assert.equal(drawTo(toggleLayer(freeView(), "hidden", "window")), 47);
  assert.equal(drawTo(toggleLayer(freeView(), "locked", "window")), 50);
});

test("hide and lock: the selection keeps only what can still be picked", () => {
  const {seg} = scene();
  const layers = toggleLayer(freeView(), "locked", "window");
  assert.deepEqual([...pickableSelection(seg, new Set([2, 3, 4]), layers)], [4]);
});

test("a reconstruction without the facade's rectangle is told it holds the elements alone", () => {
  const seg = new Segmentation(200, 100);
  seg.insert({label: "window", x0: 10, y0: 10, x1: 30, y1: 40});
  assert.match(noFacadeNote(seg), /^No facade is drawn: .* Draw the facade's outline \(class facade\)/);
  seg.insert({label: "facade", x0: 0, y0: 0, x1: 200, y1: 100});
  assert.equal(noFacadeNote(seg), "");
});
