// symdyn's robot page: the scenes of symdyn/apps/drawing/page.py drawn with three.js (inlined,
// vendor/three). Reads the JSON of the element symdyn-data; user text only through textContent.
import * as THREE from "three";

const D = JSON.parse(document.getElementById("symdyn-data").textContent);
const COLORS = { x: 0xd62728, y: 0x2ca02c, z: 0x1f77b4, link: 0x555555, loop: 0x8c564b,
  joint: 0xff7f0e, mass: 0x7f7f7f, contact: 0xe377c2, trace: 0x17becf, force: 0xbcbd22, dh: 0x9467bd };
const view = document.getElementById("view");
const W = view.clientWidth, H = view.clientHeight;
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(W, H);
renderer.setClearColor(0xffffff);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.add(new THREE.AmbientLight(0xffffff, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(3, -2, 5);
scene.add(sun);

const v3 = (a) => new THREE.Vector3(a[0], a[1], a[2]);
const center = v3(D.center), radius = Math.max(D.radius, 1e-3);
const camera = new THREE.OrthographicCamera(-1, 1, 1, -1, -100 * radius, 100 * radius);
const dirs = { iso: [1, 1, 1], front: [0, -1, 0], side: [1, 0, 0], top: [0, 0, 1] };
let az, el;
{
  const d = v3(dirs[D.view]).normalize();
  az = Math.atan2(d.y, d.x);
  el = Math.asin(d.z);
}
function placeCamera() {
  const c = Math.cos(el), d = new THREE.Vector3(c * Math.cos(az), c * Math.sin(az), Math.sin(el));
  camera.position.copy(center).addScaledVector(d, 10 * radius);
  camera.up.set(0, 0, 1);
  if (Math.abs(d.z) > 0.999) camera.up.set(-Math.sin(az), Math.cos(az), 0);
  const aspect = W / H, r = 1.15 * radius;
  camera.left = -r * Math.max(aspect, 1); camera.right = r * Math.max(aspect, 1);
  camera.top = r * Math.max(1 / aspect, 1); camera.bottom = -r * Math.max(1 / aspect, 1);
  camera.lookAt(center);
  camera.updateProjectionMatrix();
}
if (D.view === "top") { az = -Math.PI / 2; el = Math.PI / 2 - 1e-6; }
placeCamera();

const L = D.scale;
const material = (c) => new THREE.MeshLambertMaterial({ color: c });
const cylinder = new THREE.CylinderGeometry(1, 1, 1, 12);
const ball = new THREE.SphereGeometry(1, 16, 12);
function rod(color, r) {
  const m = new THREE.Mesh(cylinder, material(color));
  m.userData.r = r;
  scene.add(m);
  return m;
}
const up = new THREE.Vector3(0, 1, 0);
function placeRod(m, a, b) {
  const A = v3(a), B = v3(b), d = B.clone().sub(A), len = d.length();
  m.visible = len > 1e-12;
  if (!m.visible) return;
  m.position.copy(A).addScaledVector(d, 0.5);
  m.quaternion.setFromUnitVectors(up, d.normalize());
  m.scale.set(m.userData.r, len, m.userData.r);
}
const first = D.steps[0];
const rods = first.segments.map((s, k) => rod(D.segment_kinds[k] === "loop" ? COLORS.loop : COLORS.link,
  (D.segment_kinds[k] === "loop" ? 0.05 : 0.09) * L));
const jointRods = first.joints.map(() => rod(COLORS.joint, 0.04 * L));
const heaviest = Math.max(0, ...D.masses);
const balls = D.masses.map((m) => {
  const s = new THREE.Mesh(ball, material(COLORS.mass));
  const r = heaviest > 0 && m > 0 ? 0.25 * L * Math.cbrt(m / heaviest) : 0;
  s.scale.setScalar(Math.max(r, 1e-9));
  s.visible = r > 0;
  scene.add(s);
  return s;
});
const labels = document.getElementById("labels");
// Text with a subscript ("x" with "1": x_1), user text through textContent only.
function write(e, text, sub) {
  e.textContent = text;
  if (sub) { const s = document.createElement("sub"); s.textContent = sub; e.appendChild(s); }
}
function label(text, sub, color, kind, frame) {
  const e = document.createElement("span");
  e.className = "label " + kind;
  e.style.color = "#" + color.toString(16).padStart(6, "0");
  if (frame !== undefined) e.dataset.frame = frame;
  write(e, text, sub);
  labels.appendChild(e);
  return e;
}
const arrows = [], tags = [];
D.frames.forEach((f) => {
  const named = f.kind === "frame" || f.kind === "contact";
  const len = named ? 0.6 * L : L;
  ["x", "y", "z"].forEach((axis, k) => {
    const a = new THREE.ArrowHelper(up, new THREE.Vector3(), len, COLORS[axis], 0.25 * len, 0.12 * len);
    scene.add(a);
    arrows.push({ a, k, len });
    if (!named && axis !== "y") tags.push({ e: label(axis, f.label, COLORS[axis], "axis", f.name), frame: arrows.length - 1 });
  });
  if (named) {
    const color = f.kind === "contact" ? COLORS.contact : 0x333333;
    tags.push({ e: label(f.label, "", color, f.kind, f.name), origin: arrows.length - 1 });
  }
});
if (D.trace.length > 1) {
  const g = new THREE.BufferGeometry().setFromPoints(D.trace.map(v3));
  scene.add(new THREE.Line(g, new THREE.LineBasicMaterial({ color: COLORS.trace })));
}
const forceArrows = [];
// A DH robot's parameters at the shown step: labels beside their points, d and a along dashed
// lines (the SVG's marks, symdyn.apps.drawing.sketch.dh_texts), and the table in the corner.
const dhTags = [], dhLines = [], table = document.getElementById("dh-table");
const dashed = new THREE.LineDashedMaterial({ color: COLORS.dh, dashSize: 0.1 * L, gapSize: 0.07 * L });
function showDH(s) {
  dhTags.forEach((t) => { t.e.style.display = "none"; t.point = null; });
  dhLines.forEach((l) => { l.visible = false; });
  let n = 0;
  (s.dh || []).forEach(([text, sub, at, shift, span]) => {
    const k = dhTags.length;
    if (k <= n) dhTags.push({ e: label("", "", COLORS.dh, "dh") });
    const t = dhTags[n++];
    write(t.e, text, sub);
    t.e.style.display = "";
    t.point = v3(at);
    t.shift = shift;
    if (span) {
      const i = dhLines.findIndex((l) => !l.visible);
      const line = i >= 0 ? dhLines[i] : new THREE.Line(new THREE.BufferGeometry(), dashed);
      if (i < 0) { dhLines.push(line); scene.add(line); }
      line.geometry.setFromPoints(span.map(v3));
      line.computeLineDistances();
      line.visible = true;
    }
  });
  table.replaceChildren();
  (s.table || []).forEach((row, r) => {
    const tr = table.insertRow();
    row.forEach(([text, sub]) => {
      const cell = document.createElement(r === 0 ? "th" : "td");
      write(cell, text, sub);
      tr.appendChild(cell);
    });
  });
}

function show(k) {
  const s = D.steps[k];
  s.segments.forEach((seg, i) => placeRod(rods[i], seg[0], seg[1]));
  s.joints.forEach((j, i) => placeRod(jointRods[i], j[0], j[1]));
  s.masses.forEach((p, i) => balls[i].position.copy(v3(p)));
  let n = 0;
  s.frames.forEach((f) => {
    for (let c = 0; c < 3; c++, n++) {
      const a = arrows[n];
      a.a.position.copy(v3(f[0]));
      a.a.setDirection(new THREE.Vector3(f[1][c], f[1][c + 3], f[1][c + 6]));
    }
  });
  forceArrows.forEach((a) => { a.visible = false; });
  (s.forces || []).forEach((f, i) => {
    if (!forceArrows[i]) {
      forceArrows[i] = new THREE.ArrowHelper(up, new THREE.Vector3(), L, COLORS.force, 0.3 * L, 0.15 * L);
      scene.add(forceArrows[i]);
    }
    const d = v3(f[1]), len = d.length() * D.force_scale;
    forceArrows[i].visible = len > 1e-9;
    if (len > 1e-9) {
      forceArrows[i].position.copy(v3(f[0]));
      forceArrows[i].setDirection(d.normalize());
      forceArrows[i].setLength(len, 0.3 * L, 0.15 * L);
    }
  });
  showDH(s);
  document.getElementById("time").textContent = D.times.length > 1 ? `t = ${D.times[k].toFixed(3)} s` : "";
  render();
}
function render() {
  renderer.render(scene, camera);
  tags.forEach((t) => {
    const a = arrows[t.frame !== undefined ? t.frame : t.origin].a;
    const p = a.position.clone();
    if (t.frame !== undefined) {
      const dir = new THREE.Vector3(0, 1, 0).applyQuaternion(a.quaternion);
      p.addScaledVector(dir, arrows[t.frame].len * 1.12);
    }
    p.project(camera);
    t.e.style.left = `${((p.x + 1) / 2) * W}px`;
    t.e.style.top = `${((1 - p.y) / 2) * H}px`;
  });
  dhTags.forEach((t) => {
    if (!t.point) return;
    const p = t.point.clone().project(camera);
    t.e.style.left = `${((p.x + 1) / 2) * W + t.shift[0]}px`;
    t.e.style.top = `${((1 - p.y) / 2) * H + t.shift[1]}px`;
  });
}

const slider = document.getElementById("slider"), play = document.getElementById("play");
slider.max = String(D.steps.length - 1);
if (D.steps.length < 2) document.getElementById("controls").style.display = "none";
slider.addEventListener("input", () => show(Number(slider.value)));
let timer = null;
play.addEventListener("click", () => {
  if (timer) { clearInterval(timer); timer = null; play.textContent = "play"; return; }
  play.textContent = "pause";
  timer = setInterval(() => {
    slider.value = String((Number(slider.value) + 1) % D.steps.length);
    show(Number(slider.value));
  }, D.frame_ms);
});
let drag = null;
renderer.domElement.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; });
window.addEventListener("pointerup", () => { drag = null; });
window.addEventListener("pointermove", (e) => {
  if (!drag) return;
  az -= (e.clientX - drag[0]) * 0.01;
  el = Math.max(-1.55, Math.min(1.55, el + (e.clientY - drag[1]) * 0.01));
  drag = [e.clientX, e.clientY];
  placeCamera();
  render();
});
// The step shown first: 0, or K of a link to the page ending in #step=K.
const asked = /^#step=(\d+)$/.exec(location.hash);
slider.value = String(asked ? Math.min(Number(asked[1]), D.steps.length - 1) : 0);
show(Number(slider.value));
document.body.dataset.status = "drawn";
console.log(`symdyn: drawn ${D.frames.length} frames`);
// What the page shows as text, read back from the DOM (for tests): each label's class and text,
// the table's cells, and the count of elements no name may create.
const shown = [...document.querySelectorAll("#labels .label")].filter((e) => e.style.display !== "none");
console.log("symdyn: labels " + encodeURIComponent(JSON.stringify({
  labels: shown.map((e) => [e.className, e.dataset.frame || "", e.textContent]),
  table: [...table.rows].map((r) => [...r.cells].map((c) => c.textContent)),
  foreign: document.querySelectorAll("img, svg, iframe, object, embed, b").length,
  scripts: document.scripts.length,
})));
