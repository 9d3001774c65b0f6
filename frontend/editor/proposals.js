// Proposals as groups, DOM-free: the copies of a unit ("Find copies") and the rows and columns the proposals stand
// in, with the chips that reject or accept a whole row or column in one click, and the unit sent to the server.

/** Indices of the rectangles `ids` in the segmentation's JSON (`Segmentation.toJSON`, paint order): the `unit` of
 * a "Find copies" request. */
export function unitIndices(seg, ids) {
  const order = seg.paintOrder().map((r) => r.id);
  return [...ids].map((id) => order.indexOf(id)).filter((i) => i >= 0).sort((a, b) => a - b);
}

/** The proposals that go together with `p`: the elements of its copy of a unit (`copy`), else `p` alone. */
export function copyOf(proposals, p) {
  return p.copy === undefined ? [p] : proposals.filter((q) => q.copy === p.copy && q.reason === p.reason);
}

const middle = (p, axis) => axis === "x" ? (p.x0 + p.x1) / 2 : (p.y0 + p.y1) / 2;
const side = (p, axis) => axis === "x" ? p.x1 - p.x0 : p.y1 - p.y0;

/** Lines of proposals of one class along `axis` ("y": rows, "x": columns): proposals whose middles lie within
 * half their size of the line's first, two or more of them, each line's members in reading order. */
export function lines(proposals, axis) {
  const out = [];
  const byLabel = new Map();
  for (const p of proposals) byLabel.set(p.label, [...(byLabel.get(p.label) || []), p]);
  for (const group of byLabel.values()) {
    const sorted = [...group].sort((a, b) => middle(a, axis) - middle(b, axis));
    let line = [];
    for (const p of sorted) {
      if (line.length && middle(p, axis) - middle(line[0], axis) > side(line[0], axis) / 2) {
        if (line.length > 1) out.push(line);
        line = [];
      }
      line.push(p);
    }
    if (line.length > 1) out.push(line);
  }
  const across = axis === "y" ? "x" : "y";
  return out.map((line) => line.sort((a, b) => middle(a, across) - middle(b, across)));
}

export const CHIP = {w: 18, h: 18, gap: 4};  // screen pixels

/** The chips of the rows (left of each row's first proposal) and columns (above each column's first) of window
 * proposals, or of every class when no window is proposed, in screen pixels (`toScreen(x, y)` → [sx, sy]):
 * [{kind: "row" | "column", members, x, y, w, h}]. */
export function chips(proposals, toScreen) {
  const windows = proposals.filter((p) => p.label === "window");
  const shown = windows.length ? windows : proposals;
  const out = [];
  for (const line of lines(shown, "y")) {
    const [sx, sy0] = toScreen(line[0].x0, line[0].y0);
    const [, sy1] = toScreen(line[0].x0, line[0].y1);
    out.push({kind: "row", members: line, x: sx - CHIP.w - CHIP.gap, y: (sy0 + sy1) / 2 - CHIP.h / 2, ...CHIP});
  }
  for (const line of lines(shown, "x")) {
    const [sx0, sy] = toScreen(line[0].x0, line[0].y0);
    const [sx1] = toScreen(line[0].x1, line[0].y0);
    out.push({kind: "column", members: line, x: (sx0 + sx1) / 2 - CHIP.w / 2, y: sy - CHIP.h - CHIP.gap, ...CHIP});
  }
  return out;
}

/** The chip at screen point (sx, sy), or undefined. */
export const chipAt = (list, sx, sy) => list.find((c) => sx >= c.x && sx < c.x + c.w && sy >= c.y && sy < c.y + c.h);

/** The proposals a chip stands for, with the copies their members belong to. */
export function chipMembers(proposals, chip) {
  return [...new Set(chip.members.flatMap((p) => copyOf(proposals, p)))];
}

/** Reject the `members` (all of them, when any is still kept), or take all back when all are rejected already. */
export function toggleRejected(members) {
  const reject = members.some((p) => p.accepted !== false);
  for (const p of members) p.accepted = !reject;
  return reject;
}
