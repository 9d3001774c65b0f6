// The shortcuts with the focus in a field or on a button: typing stays with the field, but for Enter in the fields
// that run something; a button reached with Tab keeps its Enter and Space.
import assert from "node:assert/strict";
import {test} from "node:test";

import {ACTIONS, POINTER, SHORTCUTS, keyAction, parseCombo, shortcutRows} from "../editor/keys.js";

const state = (extra = {}) => ({selected: 1, proposals: 3, field: null, onButton: false, ...extra});

test("keys: Enter in the find-similar threshold runs the search again instead of accepting the proposals", () => {
  assert.deepEqual(keyAction({key: "Enter"}, state({field: "sim-threshold"})), {action: "similar"});
  assert.deepEqual(keyAction({key: "Enter"}, state()), {action: "accept"});
});

test("keys: what is typed in other fields, and any other key in the threshold field, is the field's", () => {
  assert.equal(keyAction({key: "Enter"}, state({field: "rep-cols"})), null);
  for (const key of ["r", "3", "Delete", "Backspace", "ArrowLeft", "c"]) {
    assert.equal(keyAction({key}, state({field: "sim-threshold"})), null, key);
  }
  assert.equal(keyAction({key: "z", ctrlKey: true}, state({field: "k"})), null);
});

test("keys: a focused button keeps Enter and Space; the other shortcuts still work there", () => {
  assert.equal(keyAction({key: "Enter"}, state({onButton: true})), null);
  assert.equal(keyAction({key: " "}, state({onButton: true})), null);
  assert.deepEqual(keyAction({key: "r"}, state({onButton: true})), {action: "tool", tool: "draw"});
});

// the state in which an entry of the table applies
const holding = (s) => ({selected: s.when === "selected" ? 1 : 0, proposals: s.when === "proposals" ? 2 : 0,
  help: s.when === "help", field: s.field ? s.field[0] : null});

test("help: every combo the help lists gives its entry's action (the table is what keyAction reads)", () => {
  let combos = 0;
  for (const s of SHORTCUTS) {
    s.keys.forEach((combo, i) => {
      const {ctrl, shift, key} = parseCombo(combo);
      const event = {key: /^[a-z]$/i.test(key) && !shift ? key.toLowerCase() : key, ctrlKey: ctrl, shiftKey: shift};
      const want = typeof s.action === "function" ? s.action(i) : s.action;
      assert.deepEqual(keyAction(event, holding(s)), want, combo);
      combos++;
    });
  }
  assert.ok(combos >= 30);
  const rows = shortcutRows();
  assert.equal(rows.length, SHORTCUTS.length);
  assert.ok(rows.every((r) => r.keys && r.does));
  assert.deepEqual(rows.find((r) => r.does.startsWith("redo")), {keys: "Ctrl+Shift+Z / Ctrl+Y", does: "redo"});
  assert.equal(rows.find((r) => r.does.includes("10 pixels")).keys, "Shift+ ← → ↑ ↓");
  assert.ok(POINTER.every((p) => p.keys && p.does));
  assert.ok(ACTIONS.includes("help") && ACTIONS.includes("pan") && ACTIONS.includes("label"));
});

test("help: ? opens it (typed with Shift); while open only Escape and ? act, and both close it", () => {
  assert.deepEqual(keyAction({key: "?", shiftKey: true}, {}), {action: "help", open: true});
  assert.deepEqual(keyAction({key: "Escape"}, {help: true}), {action: "help", open: false});
  assert.deepEqual(keyAction({key: "?", shiftKey: true}, {help: true}), {action: "help", open: false});
  for (const key of ["r", "Delete", "Enter", "3"]) assert.equal(keyAction({key}, {help: true, proposals: 2}), null, key);
  assert.deepEqual(keyAction({key: "Escape"}, {}), {action: "clear"});
});

test("keys: Shift and Ctrl only where the combo names them; letters in either case", () => {
  assert.deepEqual(keyAction({key: "R"}, {}), {action: "tool", tool: "draw"});  // caps lock
  assert.equal(keyAction({key: "R", shiftKey: true}, {}), null);
  assert.equal(keyAction({key: "Delete", ctrlKey: true}, {}), null);
  assert.deepEqual(keyAction({key: "z", metaKey: true}, {}), {action: "undo"});
  assert.deepEqual(keyAction({key: " "}, {}), {action: "pan"});
  assert.equal(keyAction({key: " "}, {field: "rep-cols"}), null);
});
