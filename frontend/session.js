// The editor's conversation with the site: the photo and its segmentation loaded (or a draft restored), versions
// saved, a job submitted and followed, a segmentation file read, the rectification applied.
import {ReplaceAll} from "./commands.js";
import {History} from "./history.js";
import {followJob} from "./server.js";
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
  const draft = localStorage.getItem(draftKey(photoCode));
  if (draft) {
    const {json, when} = JSON.parse(draft);
    if (confirm(`Restore the unsaved changes from ${new Date(when).toLocaleString()}?`)) {
      history.execute(new ReplaceAll(Segmentation.fromJSON(json).toJSON().rects));
    } else {
      localStorage.removeItem(draftKey(photoCode));
    }
  }
  return {info, photo, seg, history};
}

/** Keep the unsaved state in the browser (or drop it once saved). */
export function keepDraft(photoCode, seg, history) {
  if (history.dirty) localStorage.setItem(draftKey(photoCode), JSON.stringify({json: seg.toJSON(), when: Date.now()}));
  else localStorage.removeItem(draftKey(photoCode));
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
export async function readSegmentationFile(file, width, height, api) {
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
  if (parsed.width !== width || parsed.height !== height) {
    throw new Error(`the file is ${parsed.width}x${parsed.height}; the photo is ${width}x${height}`);
  }
  return {rects: parsed.toJSON().rects, warnings};
}

export async function rectify(api, photoCode, corners) {
  await api(`/api/v1/photos/${photoCode}/rectify`, {method: "POST", body: JSON.stringify({corners})});
  localStorage.removeItem(draftKey(photoCode));
}
