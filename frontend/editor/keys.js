// The editor's shortcuts as data: one table that keyAction reads to turn a key event into an action, and that the
// help overlay (`?`) lists, so that the help says what the keys do. No DOM.
import {HOTKEYS, LABELS} from "./labels.js";

const ARROWS = ["ArrowLeft", "ArrowRight", "ArrowUp", "ArrowDown"];
const STEP = {ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1]};
const nudge = (step) => (i) => ({action: "nudge", dx: STEP[ARROWS[i]][0] * step, dy: STEP[ARROWS[i]][1] * step});

// Each entry: `keys`, its combos ("Ctrl+Shift+Z", "Delete", "?"; Ctrl is also the Mac's Cmd); `action`, what it
// asks for (a function of the combo's index where the combos differ); `does`, for the help. The first that matches wins.
// `when` names what must be there: "selected" (a selection), "proposals" (proposals shown) or "help" (the help
// open; while it is, only these entries apply). `field`: the text fields whose Enter runs something; elsewhere the
// keys typed in a field are the field's.
export const SHORTCUTS = [
  {keys: ["Enter"], field: ["sim-threshold"], action: {action: "similar"},
    does: "in the find-similar threshold: search again"},
  {keys: ["Enter"], field: ["sel-x0", "sel-y0", "sel-x1", "sel-y1"], action: {action: "applyBox"},
    does: "in the selection's x0, y0, x1, y1: apply them"},
  {keys: ["Ctrl+Z"], action: {action: "undo"}, does: "undo (a drag is one step)"},
  {keys: ["Ctrl+Shift+Z", "Ctrl+Y"], action: {action: "redo"}, does: "redo"},
  {keys: ["Ctrl+D"], action: {action: "duplicate"}, does: "duplicate the selection"},
  {keys: ["Ctrl+A"], action: {action: "selectAll"}, does: "select every rectangle"},
  {keys: ["Delete", "Backspace"], action: {action: "delete"}, does: "delete the selection"},
  {keys: ["Escape"], action: {action: "clear"}, does: "clear the selection and the proposals"},
  {keys: ["R"], action: {action: "tool", tool: "draw"}, does: "the draw tool"},
  {keys: ["V"], action: {action: "tool", tool: "select"}, does: "the select tool"},
  {keys: ["C"], action: {action: "complete"}, does: "complete: propose the elements not drawn yet"},
  {keys: ["F"], action: {action: "fit"}, does: "fit the image to the screen"},
  {keys: ["Enter"], when: "proposals", action: {action: "accept"}, does: "accept the proposals not rejected"},
  {keys: HOTKEYS, action: (i) => ({action: "label", label: LABELS[i]}),
    does: `pick a class (${LABELS[0]} … ${LABELS.at(-1)}); with the select tool, relabel the selection`},
  {keys: ARROWS, when: "selected", action: nudge(1), does: "nudge the selection by 1 pixel"},
  {keys: ARROWS.map((k) => `Shift+${k}`), when: "selected", action: nudge(10), does: "nudge the selection by 10 pixels"},
  {keys: ["Space"], action: {action: "pan"}, does: "hold and drag to pan"},
  {keys: ["?"], action: {action: "help", open: true}, does: "show these shortcuts"},
  {keys: ["Escape", "?"], when: "help", action: {action: "help", open: false}, does: "close this help"},
];

// What the pointer does with modifiers (read by tools/ and editor.js, not by keyAction), for the help.
export const POINTER = [
  {keys: "wheel", does: "zoom about the cursor"},
  {keys: "middle button drag", does: "pan"},
  {keys: "Shift+click", does: "add to or take from the selection"},
  {keys: "Alt while dragging", does: "no snapping"},
  {keys: "click a proposal", does: "reject it (again: take it back)"},
  {keys: "Shift+click a proposal", does: "add it alone (one undoable step)"},
  {keys: "two fingers", does: "pinch to zoom and pan"},
];

/** A combo split into {ctrl, shift, key}; "Space" is the key " ". */
export function parseCombo(combo) {
  const parts = combo.split("+");
  const key = parts.pop() || "+";
  return {ctrl: parts.includes("Ctrl"), shift: parts.includes("Shift"), key: key === "Space" ? " " : key};
}

// Letters and named keys (Delete, ArrowLeft) match with Shift only where the combo names it; a symbol such as "?"
// is typed with Shift on most layouts, so there Shift is not looked at.
const named = (key) => key.length > 1 || /^[a-z]$/i.test(key);

function matches(combo, event) {
  const c = parseCombo(combo);
  const ctrl = Boolean(event.ctrlKey || event.metaKey);
  if (ctrl !== c.ctrl) return false;
  if (named(c.key) && Boolean(event.shiftKey) !== c.shift) return false;
  return /^[a-z]$/i.test(c.key) ? event.key.toLowerCase() === c.key.toLowerCase() : event.key === c.key;
}

/** `event`: {key, ctrlKey, metaKey, shiftKey}. `state`: {selected: how many, proposals: how many, help: whether
 * the help is open, field: the id of the focused text field or null, onButton: whether a button or link has the
 * focus}. Returns the action of the first shortcut that matches, {action, ...}, or null. */
export function keyAction(event, state = {}) {
  const {selected = 0, proposals = 0, help = false, field = null, onButton = false} = state;
  const holds = {selected: selected > 0, proposals: proposals > 0, help};
  for (const s of SHORTCUTS) {
    if (help !== (s.when === "help")) continue;
    if (s.when && !holds[s.when]) continue;
    if (field !== null && !s.field?.includes(field)) continue;
    if (field === null && s.field) continue;
    const i = s.keys.findIndex((combo) => matches(combo, event));
    if (i < 0) continue;
    // a button reached with Tab keeps its own Enter and Space (pointer clicks leave the focus on the canvas)
    if (onButton && (event.key === "Enter" || event.key === " ")) return null;
    return typeof s.action === "function" ? s.action(i) : {...s.action};
  }
  return null;
}

const SYMBOL = {ArrowLeft: "←", ArrowRight: "→", ArrowUp: "↑", ArrowDown: "↓", Escape: "Esc"};

/** The help's rows: {keys: "Ctrl+Shift+Z / Ctrl+Y", does}, a shared modifier written once ("Shift+ ← → ↑ ↓"). */
export function shortcutRows() {
  return SHORTCUTS.map((s) => {
    const shown = s.keys.map((c) => c.split("+").map((p) => SYMBOL[p] || p).join("+"));
    const cut = shown[0].lastIndexOf("+");
    const prefix = cut > 0 ? shown[0].slice(0, cut + 1) : "";
    if (shown.length > 1 && prefix && shown.every((c) => c.startsWith(prefix))) {
      return {keys: `${prefix} ${shown.map((c) => c.slice(prefix.length)).join(" ")}`, does: s.does};
    }
    const keys = shown.join(shown.every((c) => c.length === 1) ? " " : " / ");
    return {keys, does: s.does};
  });
}

/** The action names of the table, for the editor to check that it handles each. */
export const ACTIONS = [...new Set(SHORTCUTS.flatMap((s) => s.keys.map((_, i) =>
  (typeof s.action === "function" ? s.action(i) : s.action).action)))];
