// The editor's files and steps that reach the server: importing annotations (replace or merge), saving,
// submitting a reconstruction and following its job, and the rectification step (rectify-mode.js) with the
// facade's real size. `ed` is what the editor's parts share (editor.js); session.js talks to the API.
import {AddRects, ReplaceAll} from "./commands.js";
import {noFacadeNote} from "./objects.js";
import {openRectifyMode} from "./rectify-mode.js";
import {readSegmentationFile, rectify, save, submit} from "./session.js";

const $ = (sel) => document.querySelector(sel);

export function mountFiles(ed) {
  async function importJSON(file) {
    try {
      const {info} = ed;
      const original = info.rectified && info.corners ? {width: info.width, height: info.height, corners: info.corners}
        : null;  // an annotation of the photo as taken is carried through its rectification
      const {rects, warnings} = await readSegmentationFile(file, ed.seg.width, ed.seg.height, ed.api, original);
      const choice = ed.seg.size ? await askImport(ed.seg.size, rects.length) : "replace";
      if (choice === "cancel") return ed.status("Not imported: nothing changed.");
      ed.run(choice === "merge" ? new AddRects(rects, "import") : new ReplaceAll(rects));
      const drawn = ed.seg.size - rects.length;
      ed.status(`Imported ${rects.length} rectangles${choice === "merge" ? `, added to the ${drawn} ` +
        "drawn" : ""}.${warnings.map((w) => ` Note: ${w}.`).join("")}`, "success");
    } catch (err) {
      ed.status(`Not imported: ${err.message}`, "error");
    }
  }

  // "replace", "merge" or "cancel": what to do with the rectangles drawn when a file brings others
  function askImport(drawn, coming) {
    const dialog = $("#import-choice");
    $("#import-question").textContent = `${drawn} rectangles are drawn and the file has ${coming}: replace the drawn ` +
      "ones with the file's, or add the file's to them?";
    return new Promise((resolve) => {
      dialog.addEventListener("close", () => resolve(dialog.returnValue || "cancel"), {once: true});
      dialog.returnValue = "";
      dialog.showModal();
    });
  }

  async function saveNow() {
    try {
      ed.status(`Saved as version ${(await save(ed.api, ed.photoCode, ed.seg, ed.history)).version}.`, "success");
    } catch (err) {
      ed.status(`Not saved: ${err.message}`, "error");
    }
  }

  async function submitNow() {
    try {
      const k = Number($("#k").value);
      if (!Number.isInteger(k) || k < 1 || k > Number($("#k").max)) {
        return ed.status(`Not submitted: K must be a whole number from 1 to ${$("#k").max}.`, "error");
      }
      const job = await submit(ed.api, ed.photoCode, ed.seg, ed.history, {saved: ed.root.dataset.segmentation, k,
        onSaved: (code) => { ed.root.dataset.segmentation = code; },
        progress: (j) => {
          $("#job").hidden = false;
          $("#job-status").textContent = `${j.status}${j.status === "running" && j.stage ? ` (${j.stage})` : ""}` +
            (j.note ? `: ${j.note}` : "");
          $("#job-progress").value = j.progress;
        }});
      if (job.status === "failed") return ed.status(`The reconstruction failed: ${job.message}`, "error");
      ed.ui.overlay = new Image();
      ed.ui.overlay.src = `/api/v1/procedures/${job.result}/download/labels.png`;
      await ed.ui.overlay.decode();
      $("#result-link").href = `/procedures/${job.result}`;
      $("#result").hidden = false;
      const note = noFacadeNote(ed.seg);  // the elements alone, with no wall around them
      // the last message (an import's, a save's) is no longer the news: say what the job made
      ed.status(`Reconstructed: its picture is over yours; open the procedure to edit it.${note ? ` ${note}` : ""}`);
      ed.draw();
    } catch (err) {
      ed.status(`Not submitted: ${err.message}`, "error");
    }
  }

  async function openRectify() {
    ed.rectifying = await openRectifyMode(ed.canvas, $("#rectify-preview"), ed.info);
    ed.draw();  // the zoom label says the step's scale
    $("#rectify-panel").hidden = false;
    // its step in view in the side panel, which scrolls on its own: the page stays put, the save bar in view
    const panel = $("#rectify-panel"), aside = panel.closest("aside");
    if (aside) aside.scrollTop += panel.getBoundingClientRect().top - aside.getBoundingClientRect().top;
    window.scrollTo(0, 0);
    const side = ed.info.real_height_m != null ? "height" : "width";
    $("#real-side").value = side;
    $("#real-metres").value = ed.info[`real_${side}_m`] ?? "";
    ed.status("Drag the four corners onto the facade's corners; the preview shows the result.");
  }

  /** The real size typed in the rectification panel, as the photo's fields ({real_width_m: 12.5}: the other side
   * cleared; both null when the field is empty); throws a message for what is not a size. */
  function typedRealSize() {
    const input = $("#real-metres"), side = $("#real-side").value;
    const size = {real_width_m: null, real_height_m: null};
    if (input.value === "" && !input.validity.badInput) return size;
    const metres = Number(input.value);
    if (!Number.isFinite(metres) || metres < Number(input.min) || metres > Number(input.max)) {
      throw new Error(`the real ${side} must be a number of metres from ${input.min} to ${input.max}`);
    }
    return {...size, [`real_${side}_m`]: metres};
  }

  async function applyRectify() {
    const go = "Rectifying changes the image: the rectangles drawn so far do not carry over. Go on?";
    if (ed.seg.size && !confirm(go)) return;
    try {
      const size = typedRealSize();
      if (size.real_width_m !== ed.info.real_width_m || size.real_height_m !== ed.info.real_height_m) {
        const body = JSON.stringify(size);
        Object.assign(ed.info, await ed.api(`/api/v1/photos/${ed.photoCode}/`, {method: "PATCH", body}));
      }
      await rectify(ed.api, ed.photoCode, ed.rectifying.corners);
      ed.history.markSaved();
      // the editor anew on the rectified photo, saying so; without the #rectify that opened the step
      sessionStorage.setItem("facaid-rectified", ed.photoCode);
      location.replace(location.pathname + location.search);
    } catch (err) {
      ed.status(`Not rectified: ${err.message}`, "error");
    }
  }
  return {importJSON, saveNow, submitNow, openRectify, applyRectify};
}
