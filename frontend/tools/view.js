// The view: a scale and an offset (screen = image * scale + offset). Two pointers pinch to zoom and drag to pan,
// the image point under their midpoint staying under it; the whole image fits a canvas.
export const clampScale = (s) => Math.max(0.05, Math.min(40, s));

/** The view showing a `width` x `height` image whole and centred on a canvas, with a small margin. */
export function fitView(width, height, canvasWidth, canvasHeight) {
  const scale = Math.min(canvasWidth / width, canvasHeight / height) * 0.95;
  return {scale, ox: (canvasWidth - width * scale) / 2, oy: (canvasHeight - height * scale) / 2};
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
