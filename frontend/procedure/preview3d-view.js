// The 3D preview's arithmetic: where the camera and the lights go for a facade's bounds, which loaded object is an
// element and what it says. No DOM and no three.js: boxes are {min: [x, y, z], max: [x, y, z]} in metres (glTF's
// axes: x right, y up, z towards the viewer), objects anything with `userData` and `parent`.

// The default view: from the front, a little from the right and from above, so that the relief shows.
export const VIEW_DIRECTION = [0.35, 0.18, 1];

function unit(v) {
  const n = Math.hypot(...v);
  return v.map((c) => c / n);
}

function centre(box) {
  return box.min.map((lo, i) => (lo + box.max[i]) / 2);
}

/**
 * The camera that shows the whole box: looking at its centre along ``direction`` (towards the camera), far enough
 * that each of the 8 corners is within ``margin`` of the frustum of a camera of vertical field ``fovDeg`` and
 * ``aspect`` (width / height). Returns {target, position, near, far, distance}.
 */
export function fitView(box, fovDeg, aspect, {direction = VIEW_DIRECTION, margin = 1.1} = {}) {
  const target = centre(box);
  const back = unit(direction);  // from the target to the camera
  const right = unit([back[2], 0, -back[0]]);  // world up × back: the camera's x
  const up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2],
    back[0] * right[1] - back[1] * right[0]];  // back × right: the camera's y
  const tanY = Math.tan((fovDeg * Math.PI) / 360);
  const tanX = tanY * aspect;
  let distance = 0;
  let radius = 0;
  for (const x of [box.min[0], box.max[0]]) {
    for (const y of [box.min[1], box.max[1]]) {
      for (const z of [box.min[2], box.max[2]]) {
        const d = [x - target[0], y - target[1], z - target[2]];
        const along = (a) => d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
        // a corner at depth `along(back)` towards the camera is in view from this far: |offset| ≤ tan · (D − depth)
        const need = Math.max(Math.abs(along(right)) * margin / tanX, Math.abs(along(up)) * margin / tanY);
        distance = Math.max(distance, need + along(back));
        radius = Math.max(radius, Math.hypot(...d));
      }
    }
  }
  distance = Math.max(distance, radius * 0.1, 1e-3);
  return {target, position: target.map((t, i) => t + back[i] * distance), distance,
    near: Math.max(distance - radius, distance / 100) / 2, far: (distance + radius) * 4};
}

/**
 * The key light of a facade: raking from the upper left in front, so that what stands out casts a shadow on the
 * wall and what sits back lies in one; its shadow camera's half extent and depth range cover the whole box.
 */
export function keyLight(box) {
  const size = box.max.map((hi, i) => hi - box.min[i]);
  const reach = Math.max(size[0], size[1]);
  const target = centre(box);
  const offset = [-0.7 * reach, 1.0 * reach, 0.55 * reach];
  const distance = Math.hypot(...offset);
  return {target, position: target.map((t, i) => t + offset[i]), shadowHalf: 0.75 * reach,
    near: distance - reach, far: distance + reach};
}

/** The element an object belongs to: it or its nearest ancestor that carries a node's ``label`` and ``path``. */
export function elementOf(object) {
  for (let o = object; o; o = o.parent) {
    if (o.userData && typeof o.userData.label === "string" && typeof o.userData.path === "string") return o;
  }
  return null;
}

/** All elements under ``root`` (``children`` walked depth first), each counted once. */
export function elementsUnder(root) {
  const out = [];
  const walk = (o) => {
    if (elementOf(o) === o) out.push(o);
    else for (const c of o.children || []) walk(c);
  };
  walk(root);
  return out;
}

/** An element's line: its label, its node in the tree and its rectangle in the procedure's pixels. */
export function elementText(element) {
  const {label, path, box_px: box} = element.userData;
  const where = Array.isArray(box) && box.length === 4 ? ` · x ${box[0]}–${box[2]}, y ${box[1]}–${box[3]} px` : "";
  return `${label} · ${path}${where}`;
}
