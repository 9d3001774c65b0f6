// The editor's shortcuts as data: a key event's fields -> the action it asks for, or null. No DOM.
import {HOTKEYS, LABELS} from "./labels.js";

const ARROWS = {ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1]};

// Enter in these fields runs what they set (the rest of what is typed in a field stays with it)
export const FIELD_ENTER = {"sim-threshold": "similar"};

/** `event`: {key, ctrlKey, metaKey, shiftKey}. `state`: {selected: how many, proposals: how many, field: the id of
 * the focused text field or null, onButton: whether a button or link has the focus}. Returns {action, ...} with
 * action one of undo, redo, duplicate, selectAll, delete, clear, tool (tool), accept, complete, fit, label (label),
 * nudge (dx, dy), similar, or null. */
export function keyAction(event, state = {selected: 0, proposals: 0}) {
  const {key, shiftKey} = event;
  const k = key.toLowerCase();
  if (state.field != null) return key === "Enter" && FIELD_ENTER[state.field] ? {action: FIELD_ENTER[state.field]} : null;
  // a button reached with Tab keeps its own Enter and Space (pointer clicks leave the focus on the canvas)
  if (state.onButton && (key === "Enter" || key === " ")) return null;
  if (event.ctrlKey || event.metaKey) {
    if (k === "z") return {action: shiftKey ? "redo" : "undo"};
    if (k === "y") return {action: "redo"};
    if (k === "d") return {action: "duplicate"};
    if (k === "a") return {action: "selectAll"};
    return null;
  }
  if (key === "Delete" || key === "Backspace") return {action: "delete"};
  if (key === "Escape") return {action: "clear"};
  if (key === "r") return {action: "tool", tool: "draw"};
  if (key === "v") return {action: "tool", tool: "select"};
  if (k === "c") return {action: "complete"};
  if (k === "f") return {action: "fit"};
  if (key === "Enter" && state.proposals) return {action: "accept"};
  const i = HOTKEYS.indexOf(key);
  if (i >= 0) return {action: "label", label: LABELS[i]};
  if (ARROWS[key] && state.selected) {
    const step = shiftKey ? 10 : 1;
    return {action: "nudge", dx: ARROWS[key][0] * step, dy: ARROWS[key][1] * step};
  }
  return null;
}
