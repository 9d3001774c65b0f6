// The procedure page's named parameters (upper floors, floor height, tile width, ...) as a table: a name selects
// what it stands for, a value typed is asked of the server, and beside a count what the check of its edits found.

/** The table of `parameters` (the server's answer): a name's click calls `select(nodes, "parameter", name)`, a value
 * changed `ask({name: value})`. */
export function drawNamed(parameters, {select, ask}) {
  document.querySelector("#named tbody").replaceChildren(...parameters.map((p) => {
    const tr = document.createElement("tr");
    tr.dataset.name = p.name;
    tr.dataset.nodes = p.nodes.join(" ");
    const th = document.createElement("th");
    th.textContent = p.label;
    th.title = "select: what it stands for is outlined in the picture";
    th.addEventListener("click", () => select(p.nodes, "parameter", p.name));
    const input = document.createElement("input");
    input.type = "number"; input.name = p.name; input.min = p.min; input.max = p.max;
    input.step = p.integer ? 1 : 0.5; input.value = p.integer ? String(p.value) : p.value.toFixed(1);
    if (p.min === p.max) { input.disabled = true; input.title = "no repeat lays them out: edit the tree"; }
    input.addEventListener("change", () => {
      const v = Number(input.value);
      if (input.value !== "" && Number.isFinite(v)) ask({[p.name]: v});
    });
    const unit = document.createElement("td");
    unit.className = "meta"; unit.textContent = p.unit === "px" ? "px" : "";
    const td = document.createElement("td");
    td.append(input);
    tr.append(th, td, unit, checkNote(p));
    return tr;
  }));
}

// Beside a count, in words, what the server's check of its edits found (checked false: an edit of it is not clean,
// as a person would see it; null: not checked, and why); a length is not judged, and says nothing.
function checkNote(p) {
  const note = document.createElement("td");
  note.className = "check-note";
  if (p.checked === false) {
    note.classList.add("failed");
    note.textContent = (p.edits || []).filter((e) => !e.clean).map((e) => e.said).join("; ") || p.check;
  } else if (p.checked === null && p.unit === "count" && p.check) {
    note.classList.add("meta");
    note.textContent = p.check;
  }
  if (p.check && p.unit === "count") note.title = p.check;  // both edits' words
  return note;
}
