// The procedure page's history: its versions from the API (newest first), two of them picked (A and B) and
// compared side by side (both pictures, the pixels whose label differs, both accuracies against the procedure's
// segmentation), and, for the owner, revert: a new version equal to an old one, after which the page reloads.

import {makeApi, patientImage} from "../common/server.js";

const KINDS = {created: "created", edit: "edited", revert: "reverted", rerun: "re-run"};

export function accuracyText(accuracy) {
  return accuracy === null || accuracy === undefined ? "not measured" : `${(100 * accuracy).toFixed(2)} %`;
}

function cell(...content) {
  const td = document.createElement("td");
  td.append(...content);
  return td;
}

export function mountHistory({code, owner, csrf}) {
  const api = makeApi(csrf);
  const versions = `/api/v1/procedures/${code}/versions/`;
  const rows = document.querySelector("#history tbody");
  const status = document.getElementById("history-status");
  const picked = {a: null, b: null};
  let chosen = false;  // by the user: kept across refreshes; else the newest two, however many there are now

  function radio(side, version) {
    const input = document.createElement("input");
    input.type = "radio"; input.name = `compare-${side}`; input.value = version;
    input.checked = picked[side] === version;
    input.setAttribute("aria-label", `version ${version} as ${side.toUpperCase()}`);
    input.addEventListener("change", () => { picked[side] = version; chosen = true; });
    return input;
  }

  function row(v, current) {
    const tr = document.createElement("tr");
    tr.dataset.version = v.version;
    if (current) tr.className = "current";
    const made = v.note || KINDS[v.kind] || v.kind;
    const accuracy = cell(accuracyText(v.accuracy));
    if (v.warning) { accuracy.className = "worse"; accuracy.title = v.warning; }
    const actions = cell();
    if (current) actions.append("current");
    else if (owner) {
      const button = document.createElement("button");
      button.textContent = "Revert"; button.dataset.revert = v.version;
      button.title = `a new version equal to version ${v.version}`;
      actions.append(button);
    }
    tr.append(cell(radio("a", v.version)), cell(radio("b", v.version)), cell(`v${v.version}`), cell(made),
              accuracy, cell(new Date(v.created).toLocaleString()), actions);
    return tr;
  }

  async function refresh() {
    const r = await api(`${versions}?limit=100`, {raw: true, tries: 1});
    if (!r.ok) { status.textContent = "the history could not be read"; return []; }
    const {results} = await r.json();
    const known = new Set(results.map((v) => v.version));
    if (!chosen || !known.has(picked.b) || !known.has(picked.a)) {  // the current version against the one before
      picked.b = results[0]?.version ?? null;
      picked.a = results[1]?.version ?? picked.b;
    }
    rows.replaceChildren(...results.map((v, i) => row(v, i === 0)));
    return results;
  }

  async function compare(a, b) {
    status.textContent = `comparing version ${a} with version ${b}…`;
    const r = await api(`${versions}compare?a=${a}&b=${b}`, {raw: true});
    const body = await r.json().catch(() => ({}));
    if (!r.ok) { status.textContent = `could not compare: ${JSON.stringify(body)}`; return; }
    const width = Math.max(body.a.width, body.b.width);
    for (const [side, v] of [["a", body.a], ["b", body.b]]) {
      const img = document.getElementById(`compare-${side}`);
      patientImage(img, v.picture); img.style.width = `${(100 * v.width) / width}%`;
      document.getElementById(`compare-${side}-caption`).textContent =
        `${side.toUpperCase()}: version ${v.version} · pixel accuracy ${accuracyText(v.accuracy)}`;
    }
    patientImage(document.getElementById("compare-diff"), body.overlay);
    document.getElementById("compare-diff").style.width = "100%";
    const [sa, sb] = [body.a, body.b].map((v) => `${Math.round(v.width)}×${Math.round(v.height)}`);
    document.getElementById("compare-diff-caption").textContent =
      `in magenta, ${(100 * body.differing).toFixed(2)} % of the pixels: their label differs` + (sa === sb ? ""
        : ` (the two are of different sizes, ${sa} and ${sb} px: laid over each other from the top left, where ` +
          "one reaches beyond the other, the other counts as background there)");
    document.getElementById("comparison").hidden = false;
    status.textContent = "";
  }

  async function revert(version) {
    status.textContent = `reverting to version ${version}…`;
    const r = await api(`${versions}${version}/revert`, {method: "POST", raw: true, tries: 1});
    if (r.ok) { location.reload(); return; }
    const body = await r.json().catch(() => ({}));
    status.textContent = `not reverted: ${JSON.stringify(body)}`;
  }

  document.getElementById("compare").addEventListener("click", () => compare(picked.a, picked.b));
  document.addEventListener("click", (e) => {
    const target = e.target.closest("[data-revert], [data-compare]");
    if (!target) return;
    if (target.dataset.revert) revert(Number(target.dataset.revert));
    else {
      const [a, b] = target.dataset.compare.split(",").map(Number);
      picked.a = a; picked.b = b; chosen = true;
      refresh().then(() => compare(a, b));
      document.getElementById("history-panel").scrollIntoView();
    }
  });
  return {refresh, compare};
}
