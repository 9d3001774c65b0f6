// The procedure page's selection, DOM-free: which leaf a point of the picture falls in, which drawn leaves a node
// (or several) stands for, and which named parameters stand for a node. A leaf is the server's
// [label, x0, y0, x1, y1, path] in the procedure's pixels (`leaves` of /api/v1/procedures/<code>/parameters); a path
// names a node of the tree (`root/2/0`: child 0 of child 2 of the root), the same for every copy of a repeat.

/** Whether node `path` is `ancestor` or lies under it. */
export function isWithin(path, ancestor) {
  return path === ancestor || path.startsWith(`${ancestor}/`);
}

/** The leaf whose rectangle holds the point (x, y) (half-open: x0 <= x < x1), or null. Leaves do not overlap. */
export function leafAt(leaves, x, y) {
  return leaves.find(([, x0, y0, x1, y1]) => x0 <= x && x < x1 && y0 <= y && y < y1) || null;
}

/** The leaves drawn by the nodes `paths` (every copy, and everything under them). */
export function leavesUnder(leaves, paths) {
  return leaves.filter((leaf) => paths.some((p) => isWithin(leaf[5], p)));
}

/**
 * The named parameters that stand for node `path` or a node above it, innermost first: a window's leaf names the
 * window size, then the tile width, then the floor height. `parameters` are the server's ({name, nodes}); the
 * facade's width and height (the root) come last.
 */
export function parametersOf(parameters, path) {
  const depth = (p) => p.split("/").length;
  const found = [];
  for (const p of parameters) {
    const over = p.nodes.filter((node) => isWithin(path, node));
    if (over.length) found.push([Math.max(...over.map(depth)), p.name]);
  }
  return found.sort((a, b) => b[0] - a[0]).map(([, name]) => name);
}

/** The point of the procedure under a pointer at (offsetX, offsetY) on a picture shown `shownW` x `shownH`. */
export function pictureToProcedure(offsetX, offsetY, shownW, shownH, width, height) {
  return [(offsetX / shownW) * width, (offsetY / shownH) * height];
}
