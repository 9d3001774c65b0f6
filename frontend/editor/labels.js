// The 12 CMP classes, their colours and paint order: the same as facaid/labels.py (a test checks it).
export const LABELS = ["background", "facade", "window", "door", "cornice", "sill", "balcony", "blind", "deco",
  "molding", "pillar", "shop"];

export const PAINT_ORDER = ["background", "facade", "molding", "cornice", "pillar", "window", "door", "sill",
  "blind", "balcony", "shop", "deco"];

export const PALETTE = {
  background: [30, 30, 40], facade: [214, 200, 178], window: [52, 101, 164], door: [143, 89, 2],
  cornice: [245, 121, 0], sill: [252, 233, 79], balcony: [204, 0, 0], blind: [78, 154, 6],
  deco: [173, 127, 168], molding: [193, 125, 17], pillar: [136, 138, 133], shop: [32, 180, 180],
};

// number-key hotkeys: 1..9, 0, -, = pick the labels in LABELS order
export const HOTKEYS = ["1", "2", "3", "4", "5", "6", "7", "8", "9", "0", "-", "="];

export function priority(label) {
  const p = PAINT_ORDER.indexOf(label);
  if (p < 0) throw new Error(`unknown label ${JSON.stringify(label)}`);
  return p;
}

export function cssColor(label, alpha = 1) {
  const [r, g, b] = PALETTE[label];
  return alpha === 1 ? `rgb(${r}, ${g}, ${b})` : `rgba(${r}, ${g}, ${b}, ${alpha})`;
}
