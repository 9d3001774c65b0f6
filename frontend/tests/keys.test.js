// The shortcuts with the focus in a field or on a button: typing stays with the field, but for Enter in the fields
// that run something; a button reached with Tab keeps its Enter and Space.
import assert from "node:assert/strict";
import {test} from "node:test";

import {keyAction} from "../keys.js";

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
