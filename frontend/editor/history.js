// Undo and redo stacks with a cap; knows whether the document changed since it was last saved. No DOM.
export class History {
  constructor(seg, cap = 500) {
    this.seg = seg;
    this.cap = cap;
    this.done = [];
    this.undone = [];
    this.savedDepth = 0;  // done.length when last saved; -1 when that state fell off the cap
    this.listeners = new Set();
  }

  /** Run a command and record it; a command that throws changes nothing and is not recorded. */
  execute(cmd) {
    cmd.do(this.seg);
    this.done.push(cmd);
    this.undone = [];
    if (this.savedDepth > this.done.length - 1) this.savedDepth = -1;  // the saved state was in the redo stack
    if (this.done.length > this.cap) {
      this.done.shift();
      this.savedDepth = this.savedDepth > 0 ? this.savedDepth - 1 : -1;
    }
    this.emit();
    return cmd;
  }

  get canUndo() { return this.done.length > 0; }
  get canRedo() { return this.undone.length > 0; }

  undo() {
    const cmd = this.done.pop();
    if (!cmd) return null;
    cmd.undo(this.seg);
    this.undone.push(cmd);
    this.emit();
    return cmd;
  }

  redo() {
    const cmd = this.undone.pop();
    if (!cmd) return null;
    cmd.do(this.seg);
    this.done.push(cmd);
    this.emit();
    return cmd;
  }

  markSaved() { this.savedDepth = this.done.length; this.emit(); }
  get dirty() { return this.savedDepth !== this.done.length; }

  onChange(fn) { this.listeners.add(fn); return () => this.listeners.delete(fn); }
  emit() { for (const fn of this.listeners) fn(this); }
}
