// The procedure page's 3D panel: the saved procedure's relief (its facade.glb download, or facade-photo.glb with the
// photo on the fronts) in three.js, which is imported only when the panel is first opened (the import map of
// facades/_preview3d.html points "three" at the site's own static files). Orbit, zoom and pan (OrbitControls), fit
// to view, a raking key light with shadows over a soft sky light; an element under the pointer lights up and shows
// its label and tree path (the node's glTF `extras`), a click keeps it. Frames are drawn on demand, never in a loop.
// `window.facaidPreview3d` says how far it got, for the page's tests.
import {elementOf, elementsUnder, elementText, fitView, keyLight} from "./preview3d-view.js";
import {patientFetch} from "../common/server.js";

const panel = document.getElementById("preview3d");
const view = panel.querySelector(".preview3d-view");
const canvas = document.getElementById("preview3d-canvas");
const tip = document.getElementById("preview3d-tip");
const status = document.getElementById("preview3d-status");
const info = document.getElementById("preview3d-info");
const photoToggle = document.getElementById("preview3d-photo");

const state = {ready: false, loading: false, variant: null, elements: 0, frames: 0, error: null, selected: null};
window.facaidPreview3d = state;

const HOVER = 0x3a3a3a;  // emissive added to the element under the pointer
const SELECTED = 0x1f4f9b;  // and to the one clicked (the site's accent, darker)
let three = null;  // {THREE, renderer, scene, camera, controls, loader, key, raycaster}
let started = false;
const models = new Map();  // variant → {root, elements, box}
let model = null;
let hovered = null;  // the element under the pointer
let selected = null;  // the one clicked

function say(text, isError = false) {
  status.textContent = text;
  status.classList.toggle("error", isError);
}

function fail(text, error) {
  state.error = error;
  state.loading = false;
  view.hidden = true;
  panel.querySelectorAll(".preview3d-controls button, .preview3d-controls input").forEach((c) => { c.disabled = true; });
  say(text, true);
}

function hasWebGL2() {
  try {
    const gl = document.createElement("canvas").getContext("webgl2");
    gl?.getExtension("WEBGL_lose_context")?.loseContext();  // a browser keeps only a few contexts
    return Boolean(gl);
  } catch {
    return false;
  }
}

async function setUp() {
  let THREE, GLTFLoader, OrbitControls;
  try {
    [THREE, {GLTFLoader}, {OrbitControls}] = await Promise.all([import("three"),
      import("three/addons/loaders/GLTFLoader.js"), import("three/addons/controls/OrbitControls.js")]);
  } catch {
    fail("The 3D preview's files (three.js) are not installed on this server: its set-up vendors them with npm "
      + "(scripts/setup). The 3D downloads below still work.", "three.js missing");
    return null;
  }
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({canvas, antialias: true});
  } catch {
    fail("This browser could not start WebGL 2, so the 3D preview can't be shown. Download facade.glb below to "
      + "look at the facade in a 3D viewer.", "no WebGL");
    return null;
  }
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = THREE.PCFSoftShadowMap;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xeef1f4);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x9a9184, 1.1));
  const key = new THREE.DirectionalLight(0xfff3e2, 2.2);
  key.castShadow = true;
  key.shadow.mapSize.set(2048, 2048);
  key.shadow.bias = -0.0005;
  key.shadow.normalBias = 0.01;
  scene.add(key, key.target);
  const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 1000);
  const controls = new OrbitControls(camera, canvas);
  controls.screenSpacePanning = true;
  controls.addEventListener("change", draw);
  return {THREE, renderer, scene, camera, controls, key, loader: new GLTFLoader(), raycaster: new THREE.Raycaster()};
}

let framePending = false;
function draw() {
  if (framePending || !three) return;
  framePending = true;
  requestAnimationFrame(() => {
    framePending = false;
    three.renderer.render(three.scene, three.camera);
    state.frames += 1;
    if (model && !state.loading) state.ready = true;
  });
}

function resize() {
  if (!three) return;
  const width = view.clientWidth;
  const height = view.clientHeight;
  if (!width || !height) return;
  three.renderer.setSize(width, height, false);
  three.camera.aspect = width / height;
  three.camera.updateProjectionMatrix();
  draw();
}

function fit() {
  if (!model) return;
  const {camera, controls} = three;
  const v = fitView(model.box, camera.fov, camera.aspect);
  camera.position.fromArray(v.position);
  camera.near = v.near;
  camera.far = v.far;
  camera.updateProjectionMatrix();
  controls.target.fromArray(v.target);
  controls.minDistance = v.distance / 20;
  controls.maxDistance = v.distance * 6;
  controls.update();
  draw();
}

function light(box) {
  const {key} = three;
  const k = keyLight(box);
  key.position.fromArray(k.position);
  key.target.position.fromArray(k.target);
  Object.assign(key.shadow.camera, {left: -k.shadowHalf, right: k.shadowHalf, top: k.shadowHalf,
    bottom: -k.shadowHalf, near: k.near, far: k.far});
  key.shadow.camera.updateProjectionMatrix();
}

// the cached models dropped, so that the next `show` loads what is saved now; the one shown goes once replaced
function forget() {
  for (const m of models.values()) if (m !== model) dispose(m.root);
  models.clear();
}

function dispose(root) {
  root.traverse((o) => {
    if (!o.isMesh) return;
    o.geometry.dispose();
    const material = originals.get(o) || o.material;
    for (const m of [material, ...Object.values(glowing.get(material) || {})]) {
      m.map?.dispose();
      m.dispose();
    }
    glowing.delete(material);
  });
}

async function load(variant) {
  if (models.has(variant)) return models.get(variant);
  const url = panel.dataset[variant === "photo" ? "photoGlb" : "glb"];
  const r = await patientFetch(url, {credentials: "same-origin", cache: "no-cache"});
  if (!r.ok) {
    const body = await r.json().catch(() => ({}));
    throw new Error(Object.values(body).flat().join(" ") || `the server answered ${r.status}`);
  }
  const gltf = await three.loader.parseAsync(await r.arrayBuffer(), "");
  const root = gltf.scene;
  root.traverse((o) => {
    if (o.isMesh) { o.castShadow = true; o.receiveShadow = true; }
  });
  const box = new three.THREE.Box3().setFromObject(root);
  const loaded = {root, elements: elementsUnder(root), box: {min: box.min.toArray(), max: box.max.toArray()}};
  models.set(variant, loaded);
  return loaded;
}

async function show(variant) {
  state.ready = false;
  state.loading = true;
  say("Loading the 3D model…");
  if (photoToggle) photoToggle.disabled = true;  // one load at a time
  let next;
  try {
    next = await load(variant);
  } catch (err) {
    fail(`The 3D model could not be loaded: ${err.message}`, String(err.message));
    return;
  }
  if (photoToggle) photoToggle.disabled = false;
  const previous = model;
  setHovered(null);
  select(null);
  if (previous) {
    three.scene.remove(previous.root);
    if (![...models.values()].includes(previous)) dispose(previous.root);
  }
  model = next;
  three.scene.add(model.root);
  light(model.box);
  Object.assign(state, {variant, elements: model.elements.length, loading: false});
  say(`${model.elements.length} elements${variant === "photo" ? ", the photo on their fronts" : ""}. Drag to orbit, `
    + "right-drag or Shift-drag to pan, scroll to zoom; point at an element for its label and node.");
  if (!previous) fit();
  draw();
}

// highlighting: the element's meshes take a copy of their material with some glow (materials are shared by class)
const originals = new WeakMap();  // mesh → its own material
const glowing = new Map();  // original material → {kind → copy}
function glow(element, kind) {
  element.traverse((o) => {
    if (!o.isMesh) return;
    if (!originals.has(o)) originals.set(o, o.material);
    const original = originals.get(o);
    if (kind === null) { o.material = original; return; }
    if (!glowing.has(original)) glowing.set(original, {});
    const copies = glowing.get(original);
    if (!copies[kind]) {
      copies[kind] = original.clone();
      copies[kind].emissive?.setHex(kind);
    }
    o.material = copies[kind];
  });
}

function setHovered(element) {
  if (element === hovered) return;
  if (hovered) glow(hovered, hovered === selected ? SELECTED : null);
  hovered = element;
  if (hovered) glow(hovered, HOVER);
  draw();
}

function select(element) {
  if (selected && selected !== element) glow(selected, selected === hovered ? HOVER : null);
  selected = element;
  if (selected) glow(selected, SELECTED);
  state.selected = selected ? {...selected.userData} : null;
  info.textContent = selected ? `Selected: ${elementText(selected)}` : "";
  draw();
  // the page selects the same node in the tree and its parameters (selection-view.js)
  document.dispatchEvent(new CustomEvent("facaid:select3d", {detail: {path: selected?.userData.path || null}}));
}

function elementAt(event) {
  if (!model) return null;
  const rect = canvas.getBoundingClientRect();
  const pointer = new three.THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  three.raycaster.setFromCamera(pointer, three.camera);
  const hit = three.raycaster.intersectObject(model.root, true)[0];
  return hit ? elementOf(hit.object) : null;
}

function showTip(element, event) {
  tip.hidden = !element;
  if (!element) return;
  tip.textContent = elementText(element);
  const rect = view.getBoundingClientRect();
  tip.style.left = `${event.clientX - rect.left + 12}px`;
  tip.style.top = `${event.clientY - rect.top + 12}px`;
}

let down = null;
canvas.addEventListener("pointerdown", (e) => { down = [e.clientX, e.clientY]; });
canvas.addEventListener("pointermove", (e) => {
  if (e.buttons) { tip.hidden = true; return; }  // orbiting or panning
  const element = elementAt(e);
  setHovered(element);
  showTip(element, e);
});
canvas.addEventListener("pointerleave", () => { setHovered(null); tip.hidden = true; });
canvas.addEventListener("pointerup", (e) => {
  if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) <= 4) select(elementAt(e));  // a click, not a drag
  down = null;
});

async function start() {
  started = true;
  if (!hasWebGL2()) {
    fail("This browser has no WebGL 2 (it may be turned off, or the graphics driver blocked), so the 3D preview "
      + "can't be shown. Download facade.glb below to look at the facade in a 3D viewer.", "no WebGL");
    return;
  }
  say("Loading three.js…");
  three = await setUp();
  if (!three) return;
  new ResizeObserver(resize).observe(view);
  resize();
  await show(photoToggle?.checked ? "photo" : "plain");
}

// opened again: what was saved since (the cached models dropped, the camera kept)
panel.addEventListener("toggle", () => {
  if (!panel.open) return;
  if (!started) start();
  else if (model && !state.loading && !state.error) { forget(); show(state.variant); }
});
if (panel.open && !started) start();
document.getElementById("preview3d-fit").addEventListener("click", fit);
photoToggle?.addEventListener("change", () => { if (three) show(photoToggle.checked ? "photo" : "plain"); });
