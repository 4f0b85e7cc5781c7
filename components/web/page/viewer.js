// The mocap viewer page (docs/viewer.md): frames arrive as JSON over the WebSocket /ws; each
// person's 15 joints (camera frame: x right, y down, z forward, millimetres) are drawn as a
// skeleton in a stable colour per id, with the floor, the camera and its view frustum; the 2D
// keypoints beside it. Recordings (`mocap view poses.jsonl`) add a timeline the server plays.

import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";

const $ = (id) => document.getElementById(id);
const BACKGROUND = 0x15181d;

// A stable colour per person id: hues a golden angle apart.
function colourOf(id) {
  const hue = (((id * 0.6180339887) % 1) + 1) % 1;
  return new THREE.Color().setHSL(hue, 0.8, 0.55);
}
// For tests: the sRGB bytes a person's bones are drawn with.
window.viewerColour = (id) => {
  const hex = colourOf(id).getHex();
  return [(hex >> 16) & 255, (hex >> 8) & 255, hex & 255];
};

let skeleton = { joints: [], bones: [] };  // from the server's hello message
const headIndex = () => Math.max(0, skeleton.joints.indexOf("head"));

// ---- the 3D scene -------------------------------------------------------------------------
const canvas3d = $("canvas3d");
// ?aa=0 turns antialiasing off (software rendering, e.g. a headless browser, is faster without).
const antialias = new URLSearchParams(location.search).get("aa") !== "0";
// preserveDrawingBuffer: the canvas can be read back (tests count its pixels).
const renderer = new THREE.WebGLRenderer({ canvas: canvas3d, antialias, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setClearColor(BACKGROUND);
const scene = new THREE.Scene();
const view = new THREE.PerspectiveCamera(50, 1, 0.05, 200);
// The world group holds everything in camera-frame coordinates (y down, z forward); turned half a
// turn about x it shows them y up, as three.js expects.
const world = new THREE.Group();
world.rotation.x = Math.PI;
scene.add(world);
const controls = new OrbitControls(view, canvas3d);
controls.enableDamping = true;

const toWorld = (p) => world.localToWorld(p.clone());
// A camera's frame is turned half a turn about x (y down -> y up); a rig's world (frame.world) is
// turned so that its up (frame.up: the floor's normal) is three.js's +y.
let worldMode = false, upLocal = new THREE.Vector3(0, -1, 0);
function orientWorld(frame) {
  const up = frame.world && frame.up ? new THREE.Vector3(...frame.up).normalize()
                                     : new THREE.Vector3(0, -1, 0);
  if (worldMode === Boolean(frame.world) && up.equals(upLocal)) return;
  worldMode = Boolean(frame.world);
  upLocal = up;
  if (worldMode) world.quaternion.setFromUnitVectors(up, new THREE.Vector3(0, 1, 0));
  else world.rotation.set(Math.PI, 0, 0);
  world.updateMatrixWorld(true);
  viewSet = false;
}
function resetView(centre) {
  if (worldMode) {
    // A rig's world: the people seen from above and to one side, the cameras around them.
    const target = toWorld(centre);
    controls.target.copy(target);
    view.position.copy(target.clone().add(new THREE.Vector3(4.5, 4.0, 6.0)));
  } else {
    // Between the camera (the origin) and the people, seen from above, behind and to the right.
    const target = centre.clone().multiplyScalar(0.6);
    controls.target.copy(toWorld(target));
    view.position.copy(toWorld(target.clone().add(new THREE.Vector3(3.5, -2.5, -4.0))));
  }
  controls.update();
}
let lastCentre = new THREE.Vector3(0, 0.5, 3);
resetView(lastCentre);
let viewSet = false;
$("reset-view").onclick = () => resetView(lastCentre);

// Floor: a grid on the ground plane (n . x + d = 0, n up), centred under the people.
const grid = new THREE.GridHelper(12, 24, 0x6b7688, 0x3a414d);
world.add(grid);
function placeGrid(ground, centre) {
  const n = new THREE.Vector3(...ground.normal).normalize();
  const onPlane = centre.clone().sub(n.clone().multiplyScalar(n.dot(centre) + ground.offset));
  grid.position.copy(onPlane);
  grid.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), n);
  grid.material.opacity = ground.known ? 1.0 : 0.45;
  grid.material.transparent = !ground.known;
}

// The camera: a small box at the origin and its frustum to 0.8 m, from the intrinsics if known
// (else a 60 degree 4:3 guess, drawn grey).
const cameraGroup = new THREE.Group();
world.add(cameraGroup);
cameraGroup.add(new THREE.Mesh(new THREE.BoxGeometry(0.12, 0.08, 0.06),
                               new THREE.MeshBasicMaterial({ color: 0xdfe6ee })));
// Lines of a frustum to depth D in the camera's frame (x right, y down, z forward), with a roof
// on the top edge: which way is up.
function frustumLines(c, D, colour) {
  const corner = (u, v) => [((u - c.cx) / c.fx) * D, ((v - c.cy) / c.fy) * D, D];
  const k = [corner(0, 0), corner(c.width, 0), corner(c.width, c.height), corner(0, c.height)];
  const up = [((c.width / 2 - c.cx) / c.fx) * D, ((-0.15 * c.height - c.cy) / c.fy) * D, D];
  const p = [];
  for (let i = 0; i < 4; ++i) p.push(0, 0, 0, ...k[i], ...k[i], ...k[(i + 1) % 4]);
  p.push(...k[0], ...up, ...up, ...k[1]);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(p, 3));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: colour }));
}
function disposeTree(object) {
  object.traverse((o) => { if (o.geometry) o.geometry.dispose(); if (o.material) o.material.dispose(); });
}

let frustum = null, frustumKey = "";
function drawFrustum(camera) {
  const key = JSON.stringify(camera);
  if (key === frustumKey) return;
  frustumKey = key;
  if (frustum) { cameraGroup.remove(frustum); disposeTree(frustum); }
  const c = camera.known ? camera : { width: 640, height: 480, fx: 554, fy: 554, cx: 320, cy: 240 };
  frustum = frustumLines(c, 0.8, camera.known ? (camera.assumed ? 0xc9b458 : 0x7fd0ff) : 0x777777);
  cameraGroup.add(frustum);
  cameraLabel.textContent = camera.known
    ? (camera.assumed ? "camera (field of view assumed)" : "camera") : "camera (intrinsics unknown)";
}

// A rig's cameras (world-frame messages): each where it stands, its frustum to 1 m, its name.
const rigGroup = new THREE.Group();
world.add(rigGroup);
let rigKey = "", rigLabels = [];
function drawRig(cameras) {
  const key = JSON.stringify(cameras);
  if (key === rigKey) return;
  rigKey = key;
  for (const child of [...rigGroup.children]) { rigGroup.remove(child); disposeTree(child); }
  for (const l of rigLabels) l.element.remove();
  rigLabels = [];
  for (const c of cameras) {
    const g = new THREE.Group();
    const r = c.rotation;  // camera -> world, row-major
    g.matrixAutoUpdate = false;
    g.matrix.set(r[0], r[1], r[2], c.position[0], r[3], r[4], r[5], c.position[1],
                 r[6], r[7], r[8], c.position[2], 0, 0, 0, 1);
    g.add(new THREE.Mesh(new THREE.BoxGeometry(0.12, 0.08, 0.06),
                         new THREE.MeshBasicMaterial({ color: 0xdfe6ee })));
    g.add(frustumLines(c, 1.0, 0x7fd0ff));
    rigGroup.add(g);
    const element = document.createElement("div");
    element.className = "label";
    element.style.background = "#7fd0ff";
    element.textContent = c.name;
    labels.appendChild(element);
    rigLabels.push({ element, at: new THREE.Vector3(...c.position) });
  }
}

// People: bones as cylinders and joints as spheres (one instanced mesh each), unlit so that
// their colour is exact, and an HTML label with the id above the head.
const boneGeometry = new THREE.CylinderGeometry(0.022, 0.022, 1, 8);
const jointGeometry = new THREE.SphereGeometry(0.035, 10, 8);
const people = new Map();  // id -> { group, bones, joints, label }
const labels = $("labels");
const cameraLabel = document.createElement("div");
cameraLabel.className = "label";
cameraLabel.style.background = "#dfe6ee";
labels.appendChild(cameraLabel);

function personOf(id) {
  let p = people.get(id);
  if (p) return p;
  const colour = colourOf(id);
  const group = new THREE.Group();
  const bones = new THREE.InstancedMesh(boneGeometry, new THREE.MeshBasicMaterial({ color: colour }),
                                        Math.max(1, skeleton.bones.length));
  const joints = new THREE.InstancedMesh(jointGeometry,
                                         new THREE.MeshBasicMaterial({ color: colour.clone().lerp(new THREE.Color(1, 1, 1), 0.45) }),
                                         Math.max(1, skeleton.joints.length));
  bones.frustumCulled = joints.frustumCulled = false;
  group.add(bones, joints);
  world.add(group);
  const label = document.createElement("div");
  label.className = "label";
  label.style.background = colour.getStyle();
  label.textContent = "id " + id;
  labels.appendChild(label);
  p = { group, bones, joints, label, head: new THREE.Vector3() };
  people.set(id, p);
  return p;
}

function removePerson(id) {
  const p = people.get(id);
  world.remove(p.group);
  p.bones.material.dispose();
  p.joints.material.dispose();
  p.bones.dispose();
  p.joints.dispose();
  p.label.remove();
  people.delete(id);
}

const UP = new THREE.Vector3(0, 1, 0);
const matrix = new THREE.Matrix4(), quat = new THREE.Quaternion(), scale = new THREE.Vector3();
const a = new THREE.Vector3(), b = new THREE.Vector3(), dir = new THREE.Vector3();
const HIDDEN = new THREE.Matrix4().makeScale(0, 0, 0);
const jointAt = (j, i, out) =>
  j[3 * i] === null || j[3 * i + 1] === null || j[3 * i + 2] === null
    ? null : out.set(j[3 * i] / 1000, j[3 * i + 1] / 1000, j[3 * i + 2] / 1000);

function drawPerson(p, person) {
  const j = person.joints;
  skeleton.bones.forEach(([from, to], i) => {
    if (!jointAt(j, from, a) || !jointAt(j, to, b)) return p.bones.setMatrixAt(i, HIDDEN);
    dir.subVectors(b, a);
    const length = dir.length();
    if (length < 1e-6) return p.bones.setMatrixAt(i, HIDDEN);
    quat.setFromUnitVectors(UP, dir.divideScalar(length));
    matrix.compose(a.add(b).multiplyScalar(0.5), quat, scale.set(1, length, 1));
    p.bones.setMatrixAt(i, matrix);
  });
  for (let i = 0; i < skeleton.joints.length; ++i) {
    p.joints.setMatrixAt(i, jointAt(j, i, a) ? matrix.makeTranslation(a.x, a.y, a.z) : HIDDEN);
  }
  p.bones.instanceMatrix.needsUpdate = p.joints.instanceMatrix.needsUpdate = true;
  if (jointAt(j, headIndex(), a)) p.head.copy(a).addScaledVector(upLocal, 0.22);
}

function placeLabel(label, local) {
  const v = toWorld(local).project(view);
  const visible = v.z < 1 && Math.abs(v.x) < 1.2 && Math.abs(v.y) < 1.2;
  label.style.display = visible ? "" : "none";
  if (!visible) return;
  label.style.left = ((v.x + 1) / 2) * labels.clientWidth + "px";
  label.style.top = ((1 - v.y) / 2) * labels.clientHeight + "px";
}

// ---- the 2D panel -------------------------------------------------------------------------
const canvas2d = $("canvas2d");
const ctx2d = canvas2d.getContext("2d");
let extent = { w: 640, h: 480 };
function draw2d(frame) {
  if (frame.camera.known) {
    extent = { w: frame.camera.width, h: frame.camera.height };
  } else {
    for (const person of frame.people) {
      for (let i = 0; i < person.keypoints.length; i += 3) {
        if (person.keypoints[i + 2] > 0) {
          extent.w = Math.max(extent.w, Math.ceil(person.keypoints[i] / 64) * 64);
          extent.h = Math.max(extent.h, Math.ceil(person.keypoints[i + 1] / 64) * 64);
        }
      }
    }
  }
  if (canvas2d.width !== extent.w || canvas2d.height !== extent.h) {
    canvas2d.width = extent.w;
    canvas2d.height = extent.h;
  }
  const s = Math.max(1, extent.w / 640);
  ctx2d.fillStyle = "#0d0f12";
  ctx2d.fillRect(0, 0, extent.w, extent.h);
  let shown = 0;
  for (const person of frame.people) {
    const k = person.keypoints;
    const ok = (i) => k[3 * i + 2] > 0;
    const style = colourOf(person.id).getStyle();
    ctx2d.strokeStyle = ctx2d.fillStyle = style;
    ctx2d.lineWidth = 3 * s;
    for (const [from, to] of skeleton.bones) {
      if (!ok(from) || !ok(to)) continue;
      ctx2d.beginPath();
      ctx2d.moveTo(k[3 * from], k[3 * from + 1]);
      ctx2d.lineTo(k[3 * to], k[3 * to + 1]);
      ctx2d.stroke();
    }
    let any = false;
    for (let i = 0; i < k.length / 3; ++i) {
      if (!ok(i)) continue;
      any = true;
      ctx2d.beginPath();
      ctx2d.arc(k[3 * i], k[3 * i + 1], 4 * s, 0, 2 * Math.PI);
      ctx2d.fill();
    }
    const h = headIndex();
    if (ok(h)) {
      ctx2d.font = `${Math.round(14 * s)}px system-ui, sans-serif`;
      ctx2d.fillText("id " + person.id, k[3 * h] + 8 * s, k[3 * h + 1] - 10 * s);
    }
    if (any) ++shown;
  }
  if (shown === 0) {
    ctx2d.fillStyle = "#8b93a1";
    ctx2d.font = `${Math.round(16 * s)}px system-ui, sans-serif`;
    ctx2d.fillText("no 2D keypoints in this stream", 20 * s, 30 * s);
  }
}

// ---- frames ---------------------------------------------------------------------------------
const stats = { received: 0, drawn: 0, rendered: 0, people: 0, frame: null, fps: [], renderFps: [] };
window.viewerStats = stats;
let pending = null;

function applyFrame(frame) {
  orientWorld(frame);
  const seen = new Set();
  const centre = new THREE.Vector3();
  let counted = 0;
  for (const person of frame.people) {
    seen.add(person.id);
    const p = personOf(person.id);
    drawPerson(p, person);
    if (jointAt(person.joints, skeleton.joints.indexOf("root"), a)) { centre.add(a); ++counted; }
  }
  for (const id of [...people.keys()]) if (!seen.has(id)) removePerson(id);
  if (counted > 0) {
    lastCentre = centre.divideScalar(counted);
    if (!viewSet) { resetView(lastCentre); viewSet = true; }
  }
  placeGrid(frame.ground, lastCentre);
  cameraGroup.visible = !frame.world;
  if (frame.world) drawRig(frame.cameras || []);
  else drawFrustum(frame.camera);
  rigGroup.visible = Boolean(frame.world);
  draw2d(frame);
  stats.cameras = frame.world ? rigGroup.children.length : 1;
  stats.people = frame.people.length;
  stats.frame = frame.frame;
  $("people").textContent = String(frame.people.length);
  $("frame").textContent = String(frame.frame);
  if (frame.playback) showPlayback(frame.playback, frame.time);
}

// ---- the timeline of a recording ------------------------------------------------------------
let socket = null, playing = true, scrubbing = false;
const send = (message) => { if (socket && socket.readyState === 1) socket.send(JSON.stringify(message)); };
function showPlayback(pb, time) {
  $("timeline").classList.add("shown");
  playing = pb.playing;
  $("play").textContent = playing ? "pause" : "play";
  $("scrub").max = String(Math.max(0, pb.count - 1));
  if (!scrubbing) $("scrub").value = String(pb.index);
  $("clock").textContent = `${time.toFixed(2)} / ${pb.duration.toFixed(2)} s`;
  if (document.activeElement !== $("speed")) $("speed").value = String(pb.speed);
}
$("play").onclick = () => send({ cmd: playing ? "pause" : "play" });
$("scrub").addEventListener("pointerdown", () => { scrubbing = true; });
$("scrub").addEventListener("pointerup", () => { scrubbing = false; });
$("scrub").addEventListener("input", () => send({ cmd: "seek", index: Number($("scrub").value) }));
$("speed").addEventListener("change", () => send({ cmd: "speed", value: Number($("speed").value) }));

// ---- connection -----------------------------------------------------------------------------
function connect() {
  socket = new WebSocket(`ws://${location.host}/ws`);
  socket.onopen = () => { $("status").textContent = "connected"; };
  socket.onclose = () => {
    $("status").textContent = "disconnected, retrying";
    setTimeout(connect, 1000);
  };
  socket.onmessage = (event) => {
    const message = JSON.parse(event.data);
    if (message.type === "hello") {
      skeleton = { joints: message.joints, bones: message.bones };
      if (message.title) { $("title").textContent = message.title; document.title = message.title; }
    } else if (message.type === "frame") {
      ++stats.received;
      pending = message;  // only the newest frame is drawn
    }
  };
}
connect();

// ---- drawing loop -------------------------------------------------------------------------
const view3d = $("view3d");
function resize() {
  const w = view3d.clientWidth, h = view3d.clientHeight;
  renderer.setSize(w, h, false);
  view.aspect = w / Math.max(1, h);
  view.updateProjectionMatrix();
}
new ResizeObserver(resize).observe(view3d);
resize();

let windowStart = performance.now(), drawnAtStart = 0, renderedAtStart = 0;
function tick(now) {
  if (pending) {
    applyFrame(pending);
    pending = null;
    ++stats.drawn;
  }
  controls.update();
  renderer.render(scene, view);
  ++stats.rendered;
  for (const p of people.values()) placeLabel(p.label, p.head);
  if (worldMode) cameraLabel.style.display = "none";
  else placeLabel(cameraLabel, new THREE.Vector3(0, -0.12, 0));
  for (const l of rigLabels) {
    if (worldMode) placeLabel(l.element, l.at);
    else l.element.style.display = "none";
  }
  if (now - windowStart >= 1000) {
    const seconds = (now - windowStart) / 1000;
    const fps = (stats.drawn - drawnAtStart) / seconds;
    const renderFps = (stats.rendered - renderedAtStart) / seconds;
    stats.fps.push(fps);
    stats.renderFps.push(renderFps);
    $("fps").textContent = fps.toFixed(1);
    $("render-fps").textContent = renderFps.toFixed(1);
    windowStart = now;
    drawnAtStart = stats.drawn;
    renderedAtStart = stats.rendered;
  }
  requestAnimationFrame(tick);
}
requestAnimationFrame(tick);
