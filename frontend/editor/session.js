// The editor's conversation with the site: the photo and its segmentation loaded (or a draft restored), versions
// saved, a job submitted and followed, a segmentation file read, the rectification applied.
import {ReplaceAll} from "./commands.js";
import {throughRectification} from "./geometry.js";
import {History} from "./history.js";
import {followJob} from "../common/server.js";
import {Segmentation} from "./state.js";

export const draftKey = (photoCode) => `facaid-draft:${photoCode}`;

/** {info, photo, seg, history}: the photo's record and image, its segmentation (the saved version, or a draft
 * the user restores) and a history whose starting point is that version. */
export async function loadPhoto(api, photoCode, {status, forget}) {
  const info = await api(`/api/v1/photos/${photoCode}/`);
  const photo = new Image();
  photo.src = info.rectified || info.image;
  await photo.decode();
  const seg = new Segmentation(photo.naturalWidth, photo.naturalHeight);
  const history = new History(seg);
  if (info.segmentation) {
    const saved = await api(`/api/v1/segmentations/${info.segmentation}/`);
    if (saved.data.width === seg.width && saved.data.height === seg.height) {
      history.execute(new ReplaceAll(Segmentation.fromJSON(saved.data).toJSON().rects));
      history.done = [];  // the loaded version is the starting point, not an undoable step
      history.markSaved();
    } else {
      forget();
      status(`The saved segmentation (${saved.data.width}x${saved.data.height}) was drawn before rectification; ` +
        "start a new one on the rectified photo.");
    }
  }
  const draft = await newestDraft(api, photoCode, seg);
  if (draft) {
    if (confirm(`Restore the unsaved changes from ${new Date(draft.when).toLocaleString()} (kept ${draft.where})?`)) {
      history.execute(new ReplaceAll(Segmentation.fromJSON(draft.json).toJSON().rects));
    } else {
      dropDrafts(api, photoCode);
    }
  }
  return {info, photo, seg, history};
}

/** The newer of the drafts kept in this browser and on the server, {json, when, where}, if it fits the photo;
 * the server's is left out when it cannot be read (the browser's still counts). */
async function newestDraft(api, photoCode, seg) {
  const found = [];
  const local = localStorage.getItem(draftKey(photoCode));
  if (local) found.push({...JSON.parse(local), where: "in this browser"});
  try {
    const {draft} = await api(`/api/v1/photos/${photoCode}/draft`);
    if (draft) found.push({json: draft.data, when: Date.parse(draft.updated), where: "on the server"});
  } catch {
    // the server's draft is a second copy: without it the browser's is offered
  }
  const fits = found.filter((d) => d.json.width === seg.width && d.json.height === seg.height);
  return fits.sort((a, b) => b.when - a.when)[0] || null;
}

function dropDrafts(api, photoCode) {
  localStorage.removeItem(draftKey(photoCode));
  api(`/api/v1/photos/${photoCode}/draft`, {method: "DELETE"}).catch(() => {});
}

/** Keeps the unsaved state in this browser at once and on the server `delay` ms after the last change (one
 * upload at a time, in order), and drops them once it is saved; `report(text)` says where the draft stands. */
export class DraftKeeper {
  constructor(api, photoCode, report, delay = 2000) {
    Object.assign(this, {api, photoCode, report, delay, timer: null, sent: false, queue: Promise.resolve()});
  }

  keep(seg, history) {
    if (history.dirty) {
      localStorage.setItem(draftKey(this.photoCode), JSON.stringify({json: seg.toJSON(), when: Date.now()}));
    } else {
      localStorage.removeItem(draftKey(this.photoCode));
    }
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this.upload(seg, history), this.delay);
  }

  /** Send the state now (or drop the server's copy once saved); resolves when the server has answered. */
  upload(seg, history) {
    clearTimeout(this.timer);
    const dirty = history.dirty, json = dirty ? JSON.stringify(seg.toJSON()) : null;
    const url = `/api/v1/photos/${this.photoCode}/draft`;
    this.queue = this.queue.then(async () => {
      try {
        if (dirty) {
          await this.api(url, {method: "PUT", body: json});
          this.report(`draft kept on the server at ${new Date().toLocaleTimeString()}`);
        } else if (this.sent) {
          await this.api(url, {method: "DELETE"});  // back to the saved version (a save drops it there too)
          this.report("");
        }
        this.sent = dirty;
      } catch (e) {
        this.report(`the draft is not kept on the server (${e.message}); it is kept in this browser`);
      }
    });
    return this.queue;
  }
}

export async function save(api, photoCode, seg, history) {
  const body = await api(`/api/v1/photos/${photoCode}/segmentations/`, {method: "POST", body: JSON.stringify(seg.toJSON())});
  history.markSaved();
  return body;
}

/** Save if needed (`onSaved(code)` once the version is stored), submit a reconstruction of `k` candidates and
 * follow it, `progress(job)` after each poll; resolves with the finished job. `saved`: the code of the saved
 * version the editor shows, if unchanged. */
export async function submit(api, photoCode, seg, history, {saved, k = 4, onSaved, progress}) {
  const code = history.dirty || !saved ? (await save(api, photoCode, seg, history)).code : saved;
  onSaved(code);
  const job = await api("/api/v1/jobs/", {method: "POST", body: JSON.stringify({segmentation: code, k})});
  return followJob(api, job.code, progress);
}

/** {rects, warnings}: the rectangles of a segmentation file for an image of the given size, and what was read other
 * than as it stands. Our JSON is read here; COCO, LabelMe and CVAT files by the site (`POST /api/v1/convert`: of a
 * file of several images, the only one of the photo's size); throws a message otherwise. */
// the pictures a person picks instead of their annotations, by their first bytes
const PICTURES = [["ffd8ff", "a JPEG image"], ["89504e47", "a PNG image"], ["47494638", "a GIF image"],
  ["52494646", "a WebP image"], ["25504446", "a PDF document"]];

export async function readSegmentationFile(file, width, height, api, original = null) {
  const head = [...new Uint8Array(await file.slice(0, 4).arrayBuffer())]
    .map((b) => b.toString(16).padStart(2, "0")).join("");
  const picture = PICTURES.find(([magic]) => head.startsWith(magic));
  if (picture) {
    throw new Error(`this is ${picture[1]}, not annotations: import takes our segmentation JSON, COCO or ` +
      "LabelMe JSON, or CVAT XML (the photo itself is already here)");
  }
  const text = await file.text();
  let data = null, warnings = [];
  try {
    data = JSON.parse(text);
  } catch {
    // not JSON (CVAT's XML, or not a file we read): the site reads it or says why not
  }
  if (!data || typeof data !== "object" || !("rects" in data)) {
    ({segmentation: data, warnings} = await api("/api/v1/convert", {method: "POST",
      body: JSON.stringify({text, width, height})}));
  }
  const parsed = Segmentation.fromJSON(data);
  if (parsed.width === width && parsed.height === height) return {rects: parsed.toJSON().rects, warnings};
  if (original && parsed.width === original.width && parsed.height === original.height) {
    // an annotation of the photo as taken: carried through the rectification the editor knows
    const {rects, left} = throughRectification(parsed.toJSON().rects, original.corners, width, height);
    const outside = left ? `; ${left} outside the facade left out` : "";
    return {rects, warnings: [...warnings, `the file annotates the photo as taken (${original.width}x` +
      `${original.height}): its ${rects.length + left} boxes were carried through the rectification into the ` +
      `${width}x${height} facade${outside}`]};
  }
  const taken = original ? ` (as taken, before rectifying, ${original.width}x${original.height})` : "";
  throw new Error(`the file is ${parsed.width}x${parsed.height}; the photo is ${width}x${height}${taken}`);
}

export async function rectify(api, photoCode, corners) {
  await api(`/api/v1/photos/${photoCode}/rectify`, {method: "POST", body: JSON.stringify({corners})});
  localStorage.removeItem(draftKey(photoCode));  // drawn on the image before (the server drops its copy too)
}
