// The rectification step: four draggable corners on the original photo and a live preview of the warp; "Propose
// corners" places them where the server finds the facade's outermost lines, for the user to adjust.
import {applyHomography, homography, isConvexQuad, rectifiedSize} from "./geometry.js";
import {makeApi} from "../common/server.js";

const PREVIEW_SIDE = 320;

export class RectifyMode {
  constructor({canvas, preview, image, corners}) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.preview = preview;
    this.image = image;
    const w = image.naturalWidth, h = image.naturalHeight;
    this.corners = corners || [[0, 0], [w, 0], [w, h], [0, h]];
    this.dragging = -1;
    const c = document.createElement("canvas");
    c.width = w;
    c.height = h;
    const g = c.getContext("2d", {willReadFrequently: true});
    g.drawImage(image, 0, 0);
    this.pixels = g.getImageData(0, 0, w, h);
    this.fit();
  }

  fit() {
    const w = this.image.naturalWidth, h = this.image.naturalHeight;
    this.scale = Math.min(this.canvas.width / w, this.canvas.height / h) * 0.9;
    this.ox = (this.canvas.width - w * this.scale) / 2;
    this.oy = (this.canvas.height - h * this.scale) / 2;
  }

  toImage(e) { return [(e.offsetX - this.ox) / this.scale, (e.offsetY - this.oy) / this.scale]; }

  pointerdown(e) {
    const [x, y] = this.toImage(e);
    const tol = 12 / this.scale;
    this.dragging = this.corners.findIndex(([cx, cy]) => Math.abs(cx - x) <= tol && Math.abs(cy - y) <= tol);
  }

  pointermove(e) {
    if (this.dragging < 0) return;
    const [x, y] = this.toImage(e);
    const w = this.image.naturalWidth, h = this.image.naturalHeight;
    const next = this.corners.map((c) => [...c]);
    next[this.dragging] = [Math.max(0, Math.min(w, x)), Math.max(0, Math.min(h, y))];
    if (isConvexQuad(next)) this.corners = next;  // a corner may not fold the quadrilateral
    this.draw();
  }

  pointerup() {
    if (this.dragging >= 0) this.renderPreview();
    this.dragging = -1;
  }

  /** Corners from elsewhere (the server's proposal), kept inside the photo as a drag keeps them; false (and the
   * corners unchanged) when they do not make a convex quadrilateral. */
  setCorners(corners) {
    const w = this.image.naturalWidth, h = this.image.naturalHeight;
    const next = corners.map(([x, y]) => [Math.max(0, Math.min(w, x)), Math.max(0, Math.min(h, y))]);
    if (next.length !== 4 || !isConvexQuad(next)) return false;
    this.corners = next;
    this.draw();
    this.renderPreview();
    return true;
  }

  /** Ask the server for the facade's corners (`POST photos/<code>/corners/propose`) and place the handles there;
   * `say(text)` tells the user how sure the proposal is and what it guessed; `offer(whole, corners)` is given the
   * proposal's other choice where a no-data wedge cuts into the facade (the corners with the wedge in), else null. */
  async propose(api, code, say, offer = () => {}) {
    say("Looking for the facade's lines…");
    offer(null);
    try {
      const found = await api(`/api/v1/photos/${code}/corners/propose`, {method: "POST"});
      if (!this.setCorners(found.corners)) return say("The proposal was not a quadrilateral; drag the corners.");
      offer(found.whole || null, found.corners);
      const notes = found.notes.length ? ` (${found.notes.join("; ")})` : "";
      say(`Corners proposed, ${Math.round(100 * found.confidence)} % of their sides on lines found${notes}. ` +
        "Drag them to adjust.");
    } catch (err) {
      say(`No proposal: ${err.message}`);
    }
  }

  draw() {
    const {ctx, canvas} = this;
    ctx.fillStyle = "#2a2f36";
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    ctx.drawImage(this.image, this.ox, this.oy, this.image.naturalWidth * this.scale, this.image.naturalHeight * this.scale);
    ctx.strokeStyle = "#ffeb3b";
    ctx.lineWidth = 2;
    ctx.beginPath();
    this.corners.forEach(([x, y], i) => {
      const px = this.ox + x * this.scale, py = this.oy + y * this.scale;
      i === 0 ? ctx.moveTo(px, py) : ctx.lineTo(px, py);
    });
    ctx.closePath();
    ctx.stroke();
    ctx.fillStyle = "#ffeb3b";
    for (const [x, y] of this.corners) ctx.fillRect(this.ox + x * this.scale - 6, this.oy + y * this.scale - 6, 12, 12);
  }

  /** The warped photo at preview size: each output pixel samples the source through the homography. */
  renderPreview() {
    const [w, h] = rectifiedSize(this.corners);
    const s = Math.min(1, PREVIEW_SIDE / Math.max(w, h));
    const pw = Math.max(1, Math.round(w * s)), ph = Math.max(1, Math.round(h * s));
    const hm = homography([[0, 0], [pw, 0], [pw, ph], [0, ph]], this.corners);
    const out = new ImageData(pw, ph);
    const src = this.pixels;
    for (let y = 0; y < ph; y++) {
      for (let x = 0; x < pw; x++) {
        const [u, v] = applyHomography(hm, x + 0.5, y + 0.5);
        const iu = Math.min(src.width - 1, Math.max(0, Math.floor(u)));
        const iv = Math.min(src.height - 1, Math.max(0, Math.floor(v)));
        const i = 4 * (iv * src.width + iu), o = 4 * (y * pw + x);
        out.data[o] = src.data[i]; out.data[o + 1] = src.data[i + 1]; out.data[o + 2] = src.data[i + 2]; out.data[o + 3] = 255;
      }
    }
    this.preview.width = pw;
    this.preview.height = ph;
    this.preview.getContext("2d").putImageData(out, 0, 0);
    return [w, h];
  }
}

/** The rectification step opened on the original photo (`info`: the photo's API record), drawn with its preview. */
export async function openRectifyMode(canvas, preview, info) {
  const original = new Image();
  original.src = info.image;
  await original.decode();
  const mode = new RectifyMode({canvas, preview, image: original, corners: info.corners});
  mode.draw();
  mode.renderPreview();
  const button = document.getElementById("rectify-propose"), note = document.getElementById("rectify-note");
  if (button) {
    const api = makeApi(document.querySelector("meta[name=csrf-token]").content);
    const say = (text) => { if (note) note.textContent = text; };
    say("");
    button.onclick = () => mode.propose(api, info.code, say, wedgeChoice(mode));  // one handler, for the mode open now
  }
  return mode;
}

/** The "Take in the wedge" button's offer: shown where the proposal left out a part of the facade with a no-data
 * wedge, it swaps between the corners with the wedge in (`whole`) and the proposal's. */
function wedgeChoice(mode) {
  const button = document.getElementById("rectify-whole");
  return (whole, cleared) => {
    if (!button) return;
    button.hidden = !whole;
    if (!whole) return;
    let taken = false;
    button.textContent = "Take in the wedge";
    button.onclick = () => {
      taken = !taken;
      mode.setCorners(taken ? whole : cleared);
      button.textContent = taken ? "Leave the wedge out" : "Take in the wedge";
    };
  };
}
