// The procedure page's tree: every node with its breadth-first number, its sizes and counts as number fields
// (edited in place in the tree's JSON), and a repeat's exceptions; DOM built here, the page reacts through `on`.
function label(node) {
  const role = node.role ? ` · ${node.role}` : "";
  if (node.rule === "leaf") return `${node.label}${role}`;
  const extra = node.rule === "mirror" && node.center ? " (centre)" : "";
  return `${node.rule}_${node.axis}${role}${extra}`;
}

// Shown to 2 decimals (pixels and weights) or 4 (fractions): the value itself changes only when edited.
function numberInput(value, step, onChange, edited, decimals = 2) {
  const input = document.createElement("input");
  input.type = "number"; input.step = step; input.value = String(Number(value.toFixed(decimals))); input.min = 0;
  input.addEventListener("input", () => {
    const v = Number(input.value);
    if (input.value !== "" && Number.isFinite(v) && v >= 0) { onChange(v); edited(); }
  });
  return input;
}

// Each node shows its breadth-first index (#k), the order in which a re-run from a prefix keeps nodes: clicking
// it sets the re-run form to keep the nodes up to and including it.
function buildTree(node, order, on, sizeInput = null, path = "root") {
  const li = document.createElement("li");
  li.dataset.path = path;
  const k = order.get(node);
  const name = document.createElement("span");
  name.className = "node-label"; name.textContent = label(node);
  name.title = "select this node: what it draws is outlined in the picture";
  name.addEventListener("click", () => on.select(path));
  if (k !== undefined) {  // an exception's node is not among the nodes a re-run keeps
    const badge = document.createElement("span");
    badge.className = "bfs"; badge.textContent = `#${k}`;
    badge.title = `node ${k} breadth first: a re-run keeping ${k + 1} node${k ? "s" : ""} keeps #0 to #${k}`;
    badge.addEventListener("click", () => {
      const field = document.getElementById("id_nodes");
      if (field) { field.value = k + 1; field.focus(); }
    });
    li.append(badge, " ");
  }
  li.append(name);
  if (sizeInput) li.append(sizeInput);
  if (node.rule === "repeat" && node.count !== "fill") {
    li.append(" × ", numberInput(node.count, 1, (v) => { recount(node, Math.max(1, Math.round(v))); }, on.edited, 0));
  }
  if (node.children && node.children.length) {
    const ul = document.createElement("ul");
    node.children.forEach((child, i) => {
      const size = node.sizes[i];  // [mode, value]
      const span = document.createElement("span");
      const rel = size[0] === "rel";
      const input = numberInput(size[1], rel ? 0.01 : 1, (v) => { size[1] = v; }, on.edited, rel ? 4 : 2);
      span.append(` ${size[0]} `, input);
      ul.append(buildTree(child, order, on, span, `${path}/${i}`));
    });
    li.append(ul);
  }
  if (node.exceptions && node.exceptions.length) li.append(exceptionList(node, order, on, path));
  return li;
}

// A repeat's exceptions, each the copy it changes, the path of the node in it, its size and its node (the node's
// path is `${path}/!${e}`, as the server names it).
function exceptionList(node, order, on, path) {
  const ul = document.createElement("ul");
  ul.className = "exceptions";
  node.exceptions.forEach((o, e) => {
    const span = document.createElement("span");
    span.className = "exception";
    span.title = "an exception of the repeat: this copy differs from the typical one here";
    span.append(` exception: copy ${o.copy} at ${o.path.join("/")}`);
    if (o.size) {
      const rel = o.size[0] === "rel";
      span.append(` ${o.size[0]} `, numberInput(o.size[1], rel ? 0.01 : 1, (v) => { o.size[1] = v; }, on.edited,
        rel ? 4 : 2));
    }
    if (o.node) {
      ul.append(buildTree(o.node, order, on, span, `${path}/!${e}`));
    } else {
      const li = document.createElement("li");
      li.append(span);
      ul.append(li);
    }
  });
  return ul;
}

// A repeat's count set in the tree: the exceptions of copies it no longer lays out go, the tail's follow it.
function recount(node, count) {
  const old = node.count;
  node.exceptions = (node.exceptions || []).filter((o) => o.copy < count || o.copy === old)
    .map((o) => (o.copy === old ? {...o, copy: count} : o));
  if (!node.exceptions.length) delete node.exceptions;
  node.count = count;
}

function breadthFirst(root) {
  const order = new Map();
  const queue = [root];
  for (let i = 0; i < queue.length; i++) {
    order.set(queue[i], i);
    queue.push(...(queue[i].children || []));
  }
  return order;
}

/** The tree of `root` as a list element; `on.edited()` follows each change of a number, `on.select(path)` a click on
 * a node's name. */
export function treeElement(root, on) {
  const ul = document.createElement("ul");
  ul.append(buildTree(root, breadthFirst(root), on));
  return ul;
}
