// Painting the editor's canvas from its state: the photo, the rectangles in paint order with any gesture's
// preview, the rectangle being drawn, the selection and its handles, proposals, the marquee, snap guides and the
// result overlay. Reads a 2D context and the state; owns nothing.
import {handlePoints, normalize} from "./geometry.js";
import {cssColor} from "./labels.js";
import {toGray} from "./match.js";
import {shown} from "./objects.js";
import {chips} from "./proposals.js";

/** The photo's gray levels at its own size, for `match.findSimilar`. */
export function grayPixels(photo, width, height) {
  const g = Object.assign(document.createElement("canvas"), {width, height}).getContext("2d", {willReadFrequently: true});
  g.drawImage(photo, 0, 0);
  return toGray(g.getImageData(0, 0, width, height));
}

export function drawScene(ctx, {canvas, photo, seg, view, ui, fill}) {
  const sx = (x) => x * view.scale + view.ox;
  const sy = (y) => y * view.scale + view.oy;
  const box = (r) => [sx(r.x0), sy(r.y0), (r.x1 - r.x0) * view.scale, (r.y1 - r.y0) * view.scale];
  const stroke = (r, color, width = 1, dash = []) => {  // on whole pixels: crisp edges at any zoom
    ctx.setLineDash(dash);
    ctx.strokeStyle = color;
    ctx.lineWidth = width;
    const [x0, y0] = [Math.round(sx(r.x0)), Math.round(sy(r.y0))];
    ctx.strokeRect(x0 + 0.5, y0 + 0.5, Math.round(sx(r.x1)) - x0, Math.round(sy(r.y1)) - y0);
    ctx.setLineDash([]);
  };
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = "#2a2f36";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  ctx.imageSmoothingEnabled = view.scale < 1;
  ctx.filter = ui.photoFilter || "none";  // brightness and contrast of the photo layer alone
  ctx.drawImage(photo, view.ox, view.oy, seg.width * view.scale, seg.height * view.scale);
  ctx.filter = "none";
  const drag = ui.drag;
  const preview = drag?.preview || new Map();
  for (const r0 of seg.paintOrder()) {
    if (!shown(ui.layers, r0)) continue;  // a hidden class (the object list)
    const r = preview.get(r0.id) || r0;
    ctx.fillStyle = cssColor(r.label, fill);
    ctx.fillRect(...box(r));
    stroke(r, cssColor(r.label), 1);
  }
  if (drag?.kind === "draw" && drag.rect) {
    ctx.fillStyle = cssColor(ui.label, 0.4);
    ctx.fillRect(...box(drag.rect));
    stroke(drag.rect, "#fff", 1, [4, 3]);
  }
  for (const id of ui.selection) {
    const r = preview.get(id) || seg.rects.get(id);
    if (!r) continue;
    stroke(r, "#fff", 2);
    if (ui.selection.size === 1) {
      ctx.fillStyle = "#fff";
      for (const [hx, hy] of Object.values(handlePoints(r))) ctx.fillRect(sx(hx) - 3, sy(hy) - 3, 7, 7);
    }
  }
  for (const p of ui.proposals) {  // a dimmed one (the photo does not confirm it) thin until taken
    const faint = p.dimmed && !p.accepted;
    stroke(p, faint ? "#bbb" : p.accepted === false ? "#888" : "#ffeb3b", faint ? 1 : 2, faint ? [2, 3] : [6, 4]);
  }
  drawScores(ctx, ui.proposals, sx, sy, view.scale);
  for (const c of chips(ui.proposals, (x, y) => [sx(x), sy(y)])) {  // one click: a whole row or column
    const off = c.members.every((p) => p.accepted === false);
    ctx.fillStyle = off ? "#888" : "#ffeb3b";
    ctx.fillRect(c.x, c.y, c.w, c.h);
    ctx.fillStyle = "#222";
    ctx.font = "bold 13px sans-serif";
    ctx.textAlign = "center";
    ctx.fillText(off ? "↺" : "×", c.x + c.w / 2, c.y + c.h - 5);
    ctx.textAlign = "start";
  }
  if (drag?.kind === "marquee") stroke(normalize(drag.box), "#9cf", 1, [3, 3]);
  ctx.strokeStyle = "#ff4fd8";
  ctx.lineWidth = 1;
  for (const g of ui.guides) {  // on the middle of a whole pixel: a crisp line, not two half-bright ones
    ctx.beginPath();
    const [gx, gy] = [Math.round(sx(g.at)) + 0.5, Math.round(sy(g.at)) + 0.5];
    if (g.axis === "x") { ctx.moveTo(gx, 0); ctx.lineTo(gx, canvas.height); }
    else { ctx.moveTo(0, gy); ctx.lineTo(canvas.width, gy); }
    ctx.stroke();
  }
  if (ui.overlay) {
    ctx.globalAlpha = ui.overlayAlpha;
    ctx.drawImage(ui.overlay, view.ox, view.oy, seg.width * view.scale, seg.height * view.scale);
    ctx.globalAlpha = 1;
  }
}

/** Each proposal's score (two decimals) in its top-left corner, where it is wide enough on the screen to hold it. */
function drawScores(ctx, proposals, sx, sy, scale) {
  ctx.font = "11px sans-serif";
  for (const p of proposals) {
    if (p.score === undefined || (p.x1 - p.x0) * scale < 30 || (p.y1 - p.y0) * scale < 16) continue;
    const text = p.score.toFixed(2);
    ctx.fillStyle = "rgba(0, 0, 0, 0.6)";
    ctx.fillRect(sx(p.x0) + 2, sy(p.y0) + 2, ctx.measureText(text).width + 4, 13);
    ctx.fillStyle = p.accepted === false ? "#aaa" : "#ffeb3b";
    ctx.fillText(text, sx(p.x0) + 4, sy(p.y0) + 12);
  }
}
