// Proposals in the editor: find similar (in the browser, assist.js), find copies and completion (the server's
// facaid.completion.copies and facaid.complete), each shown as ghosts until accepted; the places rejected are passed
// back so that they are not proposed again. `ed` is what the editor's parts share (editor.js).
import {acceptCommand, rejectedOf, similarProposals} from "./assist.js";
import {unitIndices} from "./proposals.js";

const $ = (sel) => document.querySelector(sel);
const WALL = new Set(["facade", "background"]);  // never part of a unit of elements

export function mountProposing(ed) {
  // run again by Enter in the threshold field (keys.js), with the new threshold; the old proposals go
  function similar() {
    // with no single selection, while its proposals are shown, the search runs again for the rectangle it ran for
    const {ui, seg} = ed;
    const again = ui.proposalsFrom === "find similar" && ui.proposals.length && seg.rects.has(ui.similarSource);
    if (ed.ui.selection.size !== 1 && !again) {
      return ed.status(`Find similar looks for copies of one rectangle, and ${ed.ui.selection.size} are selected.`,
        "error");
    }
    const source = ed.ui.selection.size === 1 ? [...ed.ui.selection][0] : ed.ui.similarSource;
    const field = $("#sim-threshold"), threshold = Number(field.value);
    if (!(field.value !== "" && threshold >= Number(field.min) && threshold <= Number(field.max))) {
      return ed.status(`The threshold must be a number from ${field.min} to ${field.max}.`, "error");
    }
    ed.ui.proposals = similarProposals(ed.photoGray(), ed.seg, source, threshold);
    [ed.ui.proposalsFrom, ed.ui.similarSource] = ["find similar", source];
    const n = ed.ui.proposals.length;
    ed.status(n ? `${n} proposals at threshold ${threshold}: click one to reject it; ` +
      '"Accept" or Enter adds the rest (Enter in the threshold field searches again).'
      : `No similar places found at threshold ${threshold}.`);
    ed.draw();
  }

  // find copies (facaid.completion.copies on the server): where the selected unit, a window with what is drawn around it,
  // repeats in the photo
  async function findCopies() {
    // a unit is elements: the wall (a facade rectangle) or background selected with them is left out of it
    const elements = [...ed.ui.selection].filter((id) => !WALL.has(ed.seg.get(id)?.label));
    if (!elements.length) {
      return ed.status("Find copies looks for copies of the selected unit: a unit is elements (a window and what " +
        "belongs to it: sill, blind, hood), not the wall. Select them first: a box started on the wall takes what " +
        "it touches but the wall; locking the facade class (Objects) keeps clicks off the wall too.", "error");
    }
    const drawn = ed.seg.toJSON(), unit = unitIndices(ed.seg, elements);
    await propose({...drawn, unit}, drawn, "find copies", (n, copies) => n
      ? `${copies} ${copies === 1 ? "copy" : "copies"} of the unit (${n} proposal${n === 1 ? "" : "s"}), scored by ` +
        "how alike they look: click one to reject its copy, " +
        "a row's or column's chip to reject all of it (Shift: add it alone), Enter or \"Accept\" to add the rest."
      : `No copies of the unit found in the photo${rejectedNote()}.`);
  }

  // completion (facaid.complete on the server): the elements not drawn yet, from the rows and columns drawn so far
  async function completeNow() {
    const drawn = ed.seg.toJSON();
    await propose({...drawn}, drawn, "complete", (n, _, answer) => {
      const dim = answer.dimmed?.length || 0;
      const dimmed = dim ? `${dim} ${n ? "more " : ""}place${dim === 1 ? "" : "s"} the photo does not confirm, ` +
        "dimmed with their scores: click one to take it" : "";
      if (n) {
        return `${n} proposals: click one to reject it, Shift+click to add it alone, Enter or "Accept" to add ` +
          `the rest${dim ? `; ${dimmed}` : ""}.`;
      }
      const tried = answer.tried?.length ? ` Tried: ${answer.tried.join("; ")}.` : "";
      return `${dim ? `Nothing proposed for sure; ${dimmed}` : "Nothing to propose"}${rejectedNote()}.${tried}`;
    });
  }

  // the places rejected before are never proposed again in this session: said where nothing comes back
  const rejectedNote = () => ed.ui.rejected.length
    ? ` (${ed.ui.rejected.length} place${ed.ui.rejected.length === 1 ? "" : "s"} you rejected before ` +
      `${ed.ui.rejected.length === 1 ? "is" : "are"} not proposed again)` : "";

  // one request for proposals at a time; those shown stay until the answer replaces them (the rejected ones are
  // remembered and passed back), unless the drawing changed meanwhile
  async function propose(body, drawn, from, message) {
    if (ed.ui.completing) return;
    const known = new Set(ed.ui.rejected.map((r) => JSON.stringify(r)));
    ed.ui.rejected.push(...rejectedOf(ed.ui.proposals).filter((r) => !known.has(JSON.stringify(r))));
    body.rejected = ed.ui.rejected;
    ed.ui.completing = true;
    try {
      const answer = await ed.api(`/api/v1/photos/${ed.photoCode}/complete`,
        {method: "POST", body: JSON.stringify(body)});
      if (JSON.stringify(ed.seg.toJSON()) !== JSON.stringify(drawn)) {
        return ed.status(`The drawing changed meanwhile: ${from === "complete" ? "press C" : "ask"} again.`);
      }
      // the places the photo does not confirm come dimmed, not taken: a click takes one (`toggleRejected`)
      ed.ui.proposals = [...answer.proposals, ...(answer.dimmed || []).map((p) => ({...p, dimmed: true,
        accepted: false}))];
      ed.ui.proposalsFrom = from;
      ed.status(message(answer.proposals.length, new Set(answer.proposals.map((p) => p.copy)).size, answer));
    } catch (err) {
      ed.status(`No proposals: ${err.message}`, "error");
    } finally {
      ed.ui.completing = false;
      ed.draw();
    }
  }

  function acceptProposals() {
    const shown = ed.ui.proposals.length, dim = ed.ui.proposals.filter((p) => p.dimmed && p.accepted === false).length;
    ed.ui.rejected.push(...rejectedOf(ed.ui.proposals));
    const cmd = acceptCommand(ed.ui.proposals, ed.ui.proposalsFrom);
    ed.ui.proposals = [];
    if (cmd) ed.run(cmd);
    const added = cmd ? cmd.records.length : 0;
    ed.status(cmd ? `Added ${added} proposal${added === 1 ? "" : "s"}.` : nothingAdded(shown, dim), cmd ? "success" : "");
    ed.changed();
  }
  return {similar, findCopies, completeNow, acceptProposals};
}

/** Why Enter added nothing, of `shown` proposals of which `dim` were dimmed and not taken: "every proposal was
 * rejected" only where there were some. */
function nothingAdded(shown, dim) {
  if (!shown) {
    return "Nothing to accept: there are no proposals. Ask for some first (Complete, Find copies or Find similar).";
  }
  const untaken = dim ? `the ${dim} dimmed place${dim === 1 ? " is" : "s are"} added only when clicked` : "";
  if (shown === dim) return `Nothing was added: ${untaken}.`;
  return `Nothing was added: every proposal (${shown - dim}) was rejected${dim ? `, and ${untaken}` : ""}.`;
}
