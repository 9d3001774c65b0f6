// The procedure page's variations (procedure.js): the rows of ranges of the named parameters, and what a variant is,
// in words, for its card.

// Ranges for variations, one row per named parameter that can change (of the saved procedure, which the server
// varies): both ends given, the variations draw it within them.
let rangesDrawn = false;
export function drawRanges(parameters) {
  if (rangesDrawn) return;  // the rows keep what the user typed
  rangesDrawn = true;
  document.querySelector("#ranges tbody").replaceChildren(...parameters.filter((p) => p.min !== p.max).map((p) => {
    const tr = document.createElement("tr");
    tr.dataset.name = p.name;
    const th = document.createElement("th");
    th.textContent = p.label;
    const cells = ["from", "to"].map((end) => {
      const input = document.createElement("input");
      input.type = "number"; input.name = `${p.name}-${end}`; input.min = p.min; input.max = p.max;
      input.step = p.integer ? 1 : 0.5; input.placeholder = p.integer ? String(p.value) : p.value.toFixed(1);
      input.style.width = "6rem";
      const td = document.createElement("td");
      td.append(input);
      return td;
    });
    const unit = document.createElement("td");
    unit.className = "meta"; unit.textContent = p.unit === "px" ? "px" : "";
    tr.append(th, ...cells, unit);
    return tr;
  }));
}

// {name: [from, to]} of the rows with both ends given; a string naming the problem when a row has one end only
export function rangesAsked() {
  const out = {};
  for (const tr of document.querySelectorAll("#ranges tbody tr")) {
    const [lo, hi] = [...tr.querySelectorAll("input")].map((i) => i.value);
    if (lo === "" && hi === "") continue;
    if (lo === "" || hi === "") return `${tr.querySelector("th").textContent}: give both ends of the range`;
    out[tr.dataset.name] = [Number(lo), Number(hi)];
  }
  return out;
}

/** What a variant is, in words: "7 upper floors, 8 tiles a floor · resized to 828 × 739 px" (its counts, then what
 * made it, then the parameters a range drew: ``drawn``). */
export function variantCaption(v, drawn) {
  const c = v.meta?.counts || {};
  const plural = (n, one, many) => `${n} ${n === 1 ? one : many}`;
  const counts = [c.floors != null ? plural(c.floors, "upper floor", "upper floors") : "",
    c.bays != null ? `${plural(c.bays, "tile", "tiles")} a floor` : ""].filter(Boolean).join(", ");
  const how = {resize: `resized to ${Math.round(v.width)} × ${Math.round(v.height)} px`,
    count: "one repeat's count changed", swap: "a floor or tile swapped for another"}[v.meta?.variation] || "";
  return [counts, how, drawn].filter(Boolean).join(" · ") || "a variant";
}
