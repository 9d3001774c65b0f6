// The procedure page's variations (procedure.js): the rows of ranges of the named parameters, what a variant is,
// in words, for its card, and the cards themselves.

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

// "Show 8 variations": the server's variants of the saved procedure (by seed, within the ranges asked), each a card
// with its picture and caption; "Edit this one" loads it (`load(v)`, then the named parameters are asked again,
// `ask()`), "Save as new procedure" keeps it (`saveAsNew(v)`). `page.parameters` names what a range drew.
export function mountVariations({code, page, send, render, owner, user, load, ask, saveAsNew}) {
  document.getElementById("vary").addEventListener("click", async () => {
    const seed = Number(document.getElementById("seed").value) || 0;
    const status = document.getElementById("vary-status");
    const ranges = rangesAsked();
    if (typeof ranges === "string") { status.textContent = ranges; return; }
    const body = {n: 8, seed};
    if (Object.keys(ranges).length) body.ranges = ranges;
    if (document.getElementById("include-unchecked")?.checked) body.include_unchecked = true;
    const [r, answer] = await send(`/api/v1/procedures/${code}/variations`, "POST", body);
    const grid = document.getElementById("variants");
    if (!r.ok) {
      status.textContent = `no variations: ${answer.ranges || answer.data || answer.detail || JSON.stringify(answer)}`;
      document.getElementById("vary-left-out").hidden = true;
      return;
    }
    status.textContent = "";
    // what was not varied, and why: the counts whose edits are not clean (unless asked for)
    const leftOut = document.getElementById("vary-left-out");
    leftOut.hidden = !(answer.left_out || []).length;
    leftOut.textContent = leftOut.hidden ? "" : "Left out: " + answer.left_out.map((o) =>
      `${page.parameters.find((q) => q.name === o.name)?.label || o.name} (${o.reason})`).join("; ") +
      ". Tick \"vary those too\" to vary them anyway.";
    const {variants} = answer;
    grid.replaceChildren();
    for (const v of variants) {
      const card = document.createElement("div");
      card.className = "card";
      const img = document.createElement("img");
      img.src = await render(v);
      img.alt = v.meta?.variation || "variant";
      const caption = document.createElement("div");
      caption.className = "meta";
      const drawn = Object.entries(v.meta?.parameters || {}).map(([name, value]) => {
        const p = page.parameters.find((q) => q.name === name);
        return `${p?.label || name} ${value}${p?.unit === "px" ? " px" : ""}`;
      }).join(", ");
      caption.textContent = variantCaption(v, drawn);
      const use = document.createElement("button");
      use.textContent = "Edit this one";
      use.title = "load it into the parameters: saving it then makes a new version, or a new procedure";
      use.addEventListener("click", () => {
        load(v);
        // the variant is now the picture and the parameters above: shown there, and said
        document.getElementById("render").scrollIntoView({behavior: "smooth", block: "start"});
        const keep = owner ? "save it as a new version, or as a new procedure (Advanced)"
          : user ? "save it as a procedure of your own (Advanced)" : "log in to keep it";
        ask().then(() => {
          document.getElementById("named-status").textContent = `Loaded the variant ${caption.textContent}: ` +
            `change it, then ${keep}.`;
        });
      });
      card.append(img, caption, use);
      if (user) {
        const keep = document.createElement("button");
        keep.textContent = "Save as new procedure";
        keep.addEventListener("click", () => saveAsNew(v));
        card.append(" ", keep);
      }
      grid.append(card);
    }
  });
}
