// Panning the view (Space held, or the middle button): the offset follows the pointer in screen pixels.
export class PanGesture {
  constructor(pointer, view) {
    this.kind = "pan";
    this.sx = pointer.sx;
    this.sy = pointer.sy;
    this.ox = view.ox;
    this.oy = view.oy;
  }

  move(pointer) {
    return {guides: [], view: {ox: this.ox + pointer.sx - this.sx, oy: this.oy + pointer.sy - this.sy}};
  }

  up() {
    return {};
  }
}
