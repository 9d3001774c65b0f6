// The view: a scale and an offset (screen = image * scale + offset). Two pointers pinch to zoom and drag to pan,
// the image point under their midpoint staying under it; the whole image fits a canvas.
export const clampScale = (s) => Math.max(0.05, Math.min(40, s));

export const PHOTO_ADJUST = {min: 0.2, max: 4};  // brightness and contrast, as factors of the photo's own

/** The canvas filter that shows the photo brighter or with more contrast ("none" as it is): the photo layer only,
 * for seeing into dark photos; the photo itself, what find similar reads and what is saved, stay as they are. */
export function photoFilter({brightness = 1, contrast = 1} = {}) {
  const factor = (v) => (Number.isFinite(v) ? Math.max(PHOTO_ADJUST.min, Math.min(PHOTO_ADJUST.max, v)) : 1);
  const [b, c] = [factor(brightness), factor(contrast)];
  return b === 1 && c === 1 ? "none" : `brightness(${b}) contrast(${c})`;
}

/** The view showing a `width` x `height` image whole and centred on a canvas, with a small margin. */
export function fitView(width, height, canvasWidth, canvasHeight) {
  const scale = Math.min(canvasWidth / width, canvasHeight / height) * 0.95;
  return {scale, ox: (canvasWidth - width * scale) / 2, oy: (canvasHeight - height * scale) / 2};
}

/** The view with `rect` (image pixels) in sight: unchanged when it already is whole, else centred on it at the
 * same scale. */
export function reveal(view, rect, canvasWidth, canvasHeight) {
  const [x0, y0] = [rect.x0 * view.scale + view.ox, rect.y0 * view.scale + view.oy];
  const [x1, y1] = [rect.x1 * view.scale + view.ox, rect.y1 * view.scale + view.oy];
  if (x0 >= 0 && y0 >= 0 && x1 <= canvasWidth && y1 <= canvasHeight) return {...view};
  return {scale: view.scale, ox: canvasWidth / 2 - (rect.x0 + rect.x1) / 2 * view.scale,
    oy: canvasHeight / 2 - (rect.y0 + rect.y1) / 2 * view.scale};
}

function midpoint(points) {
  const [[ax, ay], [bx, by]] = points;
  return {mx: (ax + bx) / 2, my: (ay + by) / 2, dist: Math.hypot(bx - ax, by - ay) || 1};
}

export class PinchGesture {
  /** `points`: the two pointers' [sx, sy]; `view`: {scale, ox, oy}. */
  constructor(points, view) {
    this.kind = "pinch";
    const p = midpoint(points);
    this.dist = p.dist;
    this.scale = view.scale;
    this.anchor = [(p.mx - view.ox) / view.scale, (p.my - view.oy) / view.scale];
  }

  /** The view for the pointers' new positions. */
  view(points) {
    const p = midpoint(points);
    const scale = clampScale(this.scale * p.dist / this.dist);
    return {scale, ox: p.mx - this.anchor[0] * scale, oy: p.my - this.anchor[1] * scale};
  }
}
