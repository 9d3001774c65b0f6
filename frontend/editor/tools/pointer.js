// Pointer input on the editor's canvas, as miniPaint keeps it: the gestures live in tools/, the page only wires
// them. Presses, moves and releases become the tools' previews and commands (select.js decides what a press
// starts), two fingers pinch, the wheel zooms around the cursor, and a click on a proposal or on a row's chip
// rejects it (Shift: accepts it) before any tool sees the press. `ed` is what the editor's parts share (editor.js).
import {acceptCommand, proposalAt} from "../assist.js";
import {chipAt, chipMembers, chips, copyOf, toggleRejected} from "../proposals.js";
import {press} from "./select.js";
import {PinchGesture, clampScale} from "./view.js";

const $ = (sel) => document.querySelector(sel);

/** Listen to `ed.canvas`; `readout(x, y)` shows the cursor's image position, `afterDrawn()` follows a drawn one. */
export function mountPointer(ed, {readout, afterDrawn}) {
  const chipUnder = (e) => chipAt(chips(ed.ui.proposals, ed.toScreen), e.offsetX, e.offsetY);
  const toolContext = () => ({seg: ed.seg, selection: ed.ui.selection, label: ed.ui.label, scale: ed.view.scale,
    snap: $("#snap").checked,
    layers: ed.ui.layers});
  const pointers = new Map();  // pointerId -> [offsetX, offsetY] while down: two pinch

  function pointerOf(e) {
    const [x, y] = ed.toImage(e.offsetX, e.offsetY);
    return {x, y, sx: e.offsetX, sy: e.offsetY, shift: e.shiftKey, alt: e.altKey};
  }

  ed.canvas.addEventListener("pointerdown", (e) => {
    ed.canvas.setPointerCapture(e.pointerId);
    if (ed.rectifying) return ed.rectifying.pointerdown(e);
    pointers.set(e.pointerId, [e.offsetX, e.offsetY]);
    if (pointers.size > 2) return;
    if (pointers.size === 2) {  // a gesture started by the first finger is dropped
      ed.ui.drag = new PinchGesture([...pointers.values()], ed.view);
      ed.ui.guides = [];
      return ed.draw();
    }
    const pan = ed.ui.space || e.button === 1;
    // a press on a proposal or a row's chip is the start of a click that rejects it (below): it selects and moves
    // nothing under it
    if (!pan && (chipUnder(e) || proposalAt(ed.ui.proposals, ...ed.toImage(e.offsetX, e.offsetY)))) return;
    const {gesture, selection} = press(ed.ui.tool, pointerOf(e), toolContext(), ed.view, {pan});
    ed.ui.drag = gesture;
    ed.ui.selection = selection;
    ed.changed();
  });

  ed.canvas.addEventListener("pointermove", (e) => {
    if (ed.seg && !ed.rectifying) readout(...ed.toImage(e.offsetX, e.offsetY));
    if (ed.rectifying) return ed.rectifying.pointermove(e);
    if (pointers.has(e.pointerId)) pointers.set(e.pointerId, [e.offsetX, e.offsetY]);
    const d = ed.ui.drag;
    if (!d) return;
    if (d.kind === "pinch") {
      if (pointers.size >= 2) Object.assign(ed.view, d.view([...pointers.values()]));
      return ed.draw();
    }
    const result = d.move(pointerOf(e), toolContext());
    ed.ui.guides = result.guides;
    if (result.view) Object.assign(ed.view, result.view);
    ed.draw();
  });

  ed.canvas.addEventListener("pointercancel", (e) => {  // the browser took the gesture: nothing is committed
    pointers.delete(e.pointerId);
    if (!ed.rectifying) [ed.ui.drag, ed.ui.guides] = [null, []];
    ed.draw();
  });

  ed.canvas.addEventListener("pointerup", (e) => {
    pointers.delete(e.pointerId);
    if (ed.rectifying) return ed.rectifying.pointerup();
    const d = ed.ui.drag;
    ed.ui.drag = null;
    ed.ui.guides = [];
    if (!d || d.kind === "pinch") return ed.draw();
    const {command, selection, selectAdded} = d.up(toolContext());
    if (selection) ed.ui.selection = selection;
    if (command) {
      ed.run(command);
      if (selectAdded && command.ids) ed.ui.selection = new Set(command.ids);
    }
    ed.changed();
    if (d.kind === "draw" && command) afterDrawn();  // proposals after each drawn one, where asked for
  });

  ed.canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const [x, y] = ed.toImage(e.offsetX, e.offsetY);
    ed.view.scale = clampScale(ed.view.scale * Math.exp(-e.deltaY * 0.0015));
    ed.view.ox = e.offsetX - x * ed.view.scale;
    ed.view.oy = e.offsetY - y * ed.view.scale;
    ed.draw();
  }, {passive: false});

  // proposals: a click rejects (or takes back) one, with the rest of its copy, before any tool sees the press;
  // Shift+click accepts it alone; a row's or column's chip does the same for all of the row or column
  ed.canvas.addEventListener("click", (e) => {
    if (ed.ui.drag) return;
    const chip = chipUnder(e);
    const p = chip ? null : proposalAt(ed.ui.proposals, ...ed.toImage(e.offsetX, e.offsetY));
    const members = chip ? chipMembers(ed.ui.proposals, chip) : p ? copyOf(ed.ui.proposals, p) : [];
    if (!members.length) return;
    if (e.shiftKey) {  // a row or column adds what is not rejected in it; one proposal is added as it is
      const taken = chip ? members.filter((q) => q.accepted !== false) : members;
      ed.ui.proposals = ed.ui.proposals.filter((q) => !taken.includes(q));
      const what = chip ? `a ${chip.kind} of ${taken.length}` : `one ${p.label}`;
      if (taken.length) ed.run(acceptCommand(taken.map((q) => ({...q, accepted: true})), `accept ${what}`));
      ed.changed();
    } else {
      const rejected = toggleRejected(members);
      if (chip) ed.status(`${rejected ? "Rejected" : "Took back"} a ${chip.kind} of ${members.length} proposals.`);
      ed.draw();
    }
  }, true);
}
