// The edo-city viewer: the builds `edo-city serve` lists (hypotheses of one place), each a
// 3D Tiles 1.1 tileset of GLB tiles, in one scene with one camera, so switching between them
// (button, [ ] or H keys, /?h=K, window.edoCity.show(K)) keeps the view; a split view shows
// the current one left and the next one right. Clicking an object shows its metadata
// (EXT_structural_metadata); links of the build (links.json) are markers that open their page.
//
// The scene frame is the build's own: x east, y up, z south, metres from the output origin
// (the OBJ tiles' frame): the tileset's root transform (origin -> ECEF) is undone and z-up
// turned y-up, so every hypothesis placed on the globe lands in the same place here.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TilesRenderer } from '3d-tiles-renderer';
import { GLTFExtensionsPlugin } from '3d-tiles-renderer/plugins';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { createDesigner } from './garden.js';
import { createCrowd, lambdaChart, nearestStretch } from './crowd.js';
import { createWorkbench } from './workbench.js';

const SKY = 0xbcd6ea;
const EYE = 1.6;

const api = (window.edoCity = {
  ready: false,
  tiles: 0,
  hypotheses: [],
  current: 0,
  info: null,
  errors: [],
  openLinks: true,
  show: (k) => show(k),
  lookAt: (east, north, up, height) => lookAt(east, north, up, height),
  lookFrom: (east, north, up) => lookFrom(east, north, up),
  camera: () => ({ position: camera.position.toArray(), target: controls.target.toArray() }),
  screenOf: (east, north, up) => screenOf(east, north, up),
  sample: () => sample(),
  groundAt: (x, z) => groundAt({ x, z }),
  setSplit: (on) => setSplit(on),
  // The viewer's own numbers, for the level-of-detail budgets (issue 40): the last frame's
  // draw calls and triangles, the tiles loaded of the current build, the bytes of the
  // builds' files fetched so far (bodies that came over the network: a response from the
  // browser's cache, or a 304 revalidation, sends none; every tile's loader asks for the
  // shared textures again) and the frames a second (over the last second, or the last frame when it took longer).
  stats: {
    drawCalls: 0,
    triangles: 0,
    tilesLoaded: 0,
    fps: 0,
    get bytesFetched() {
      return performance
        .getEntriesByType('resource')
        .filter((e) => new URL(e.name).pathname.startsWith('/h/'))
        .filter((e) => e.transferSize >= e.encodedBodySize)
        .reduce((sum, e) => sum + (e.encodedBodySize || 0), 0);
    },
  },
});
// The walkers' clips: playing from the start, paused with the panel's button or P.
const crowd = createCrowd();
api.crowd = crowd.api;
// Every tile's fetch stays counted (the browser keeps 250 entries by default).
performance.setResourceTimingBufferSize(1000000);

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
// Counted per frame (split view renders twice): reset by the animation loop.
renderer.info.autoReset = false;
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(SKY);
renderer.setScissorTest(false);
document.body.appendChild(renderer.domElement);

const scene = new THREE.Scene();
api.scene = scene;
scene.add(new THREE.HemisphereLight(0xffffff, 0x8a7f6a, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(0.4, 1.0, 0.25);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(50, window.innerWidth / window.innerHeight, 0.5, 20000);
const controls = new OrbitControls(camera, renderer.domElement);
controls.enableDamping = false;
controls.maxPolarAngle = Math.PI * 0.495;

api.garden = createDesigner({
  scene,
  point: (east, north, up) => point(east, north, up),
  render: () => render(),
  build: () => api.current,
  hideStones: (on) => {
    designing = on;
    for (const c of cities) if (c) applyToggles(c.tiles.group);
  },
  // The garden in the left part of the picture: the designer's panel covers the right.
  frame: (east, north, up, size) => {
    if (walking) toggleWalk();
    const p = point(east, north, up);
    const d = Math.max(size, 10);
    camera.position.set(p.x - 0.9 * d, p.y + 1.3 * d, p.z + 1.0 * d);
    controls.target.copy(p);
    controls.update();
    camera.updateMatrixWorld();
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const shift = right.multiplyScalar(0.55 * d);
    camera.position.add(shift);
    controls.target.add(shift);
    controls.update();
    render();
  },
});

// The workbench of `serve --edit`: its panel shows only when the server edits a hypothesis.
const workbench = createWorkbench({
  scene,
  point: (east, north, up) => point(east, north, up),
  render: () => render(),
  reload: (rev) => reloadBuild(0, rev),
  base: '/h/0/',
});
api.edit = workbench.api;

const params = new URLSearchParams(location.search);
const hidden = new Set();
let split = false;
let walking = false;
let placement = null; // Matrix4: ECEF -> scene
let sceneOrigin = [0, 0]; // map metres (east, north) of the scene's origin
const cities = []; // per hypothesis: { tiles, models: Set, links: Group|null }
const status = document.getElementById('status');

/** The matrix taking ECEF to the scene: inverse of the first build's root transform, then z-up to y-up. */
function placementOf(tileset) {
  const root = new THREE.Matrix4().fromArray(tileset.root.transform);
  const zUpToYUp = new THREE.Matrix4().makeRotationX(-Math.PI / 2);
  return zUpToYUp.multiply(root.invert());
}

/** Hides or shows the nodes of the hidden kinds in one loaded model (the tiles' stones also
 * while the garden designer stands a candidate in their place). */
function applyToggles(object) {
  object.traverse((o) => {
    if (o.userData.kind === undefined) return;
    o.visible = !hidden.has(o.userData.kind) && !(designing && o.userData.kind === 'stone');
  });
}
let designing = false;

function city(k, url) {
  if (cities[k]) return cities[k];
  const h = api.hypotheses[k];
  const tiles = new TilesRenderer(url || h.tileset);
  // Tiles are EXT_meshopt_compression by default ([output] glb_compression): three.js' own
  // decoder (WebAssembly, served from the pinned npm package) unpacks them.
  tiles.registerPlugin(new GLTFExtensionsPlugin({ metadata: true, rtc: true, meshoptDecoder: MeshoptDecoder }));
  // The workbench's rebuilds of the first build: changed tiles by their revision.
  if (k === 0) tiles.registerPlugin(workbench.urls());
  // The tileset's parents are the city in coarser levels, each replaced by its children when
  // its measured error would cover more than 16 pixels (CesiumJS' default): the whole town
  // from above is the root alone; a street's tiles come in full as the camera nears them.
  tiles.errorTarget = 16;
  tiles.setCamera(camera);
  tiles.setResolutionFromRenderer(camera, renderer);
  tiles.group.matrixAutoUpdate = false;
  tiles.group.matrix.copy(placement);
  tiles.group.matrixWorldNeedsUpdate = true;
  const c = { tiles, models: new Set(), grounds: new Map(), links: null, loaded: false };
  tiles.addEventListener('load-model', ({ scene: model, tile }) => {
    // Each node of a tile is one object kind (machiya, kura, fence, people, ...): its
    // glTF extras, which three.js puts in userData.kind.
    applyToggles(model);
    // A tile's walkers are skinned meshes (a draw call per 32 walkers): three.js would cull
    // one by its bounding sphere at the pose it first saw, while the walkers walk on. The
    // tile's own box holds the whole clip, and the renderer culls tiles by it.
    model.traverse((o) => {
      if (o.isSkinnedMesh) o.frustumCulled = false;
    });
    c.models.add(tile);
    // The tile's ground and streets, which walking stands on.
    const under = [];
    model.traverse((o) => {
      if (o.userData.kind === 'ground' || o.userData.kind === 'streets') {
        o.traverse((m) => { if (m.isMesh) under.push(m); });
      }
    });
    c.grounds.set(tile, under);
    crowd.add(tile, model, tile.engineData && tile.engineData.metadata && tile.engineData.metadata.animations);
    if (k === api.current) api.tiles = c.models.size;
  });
  tiles.addEventListener('dispose-model', ({ tile }) => {
    c.grounds.delete(tile);
    crowd.remove(tile);
  });
  tiles.addEventListener('load-error', ({ url, error }) => {
    api.errors.push(`${url}: ${error}`);
    console.error('tile failed to load', url, error);
  });
  tiles.addEventListener('tiles-load-end', () => {
    c.loaded = true;
    if (k === api.current) markReady();
  });
  scene.add(tiles.group);
  if (h.links) loadLinks(k, c);
  cities[k] = c;
  return c;
}

/** Build k loaded again after the workbench rebuilt it (revision `rev`): the tileset's
 * URL changes, so every tile is asked for again; those that did not change come back as
 * 304 from the browser's cache (the server sends `no-cache`: revalidate, never a stale one).
 * Resolves once it is shown (at once when it is not on screen). */
function reloadBuild(k, rev) {
  const old = cities[k];
  if (old) {
    scene.remove(old.tiles.group);
    if (old.links) scene.remove(old.links);
    old.tiles.dispose();
  }
  cities[k] = null;
  const c = city(k, `${api.hypotheses[k].tileset}?rev=${rev}`);
  show(api.current);
  if (!c.tiles.group.visible) return Promise.resolve();
  return until(() => api.ready && c.loaded && c.tiles.loadProgress === 1);
}

/** Resolves when `done()` holds, looked at every frame (a minute at most). */
function until(done) {
  const t0 = performance.now();
  return new Promise((resolve, reject) => {
    const look = () => {
      if (done()) resolve();
      else if (performance.now() - t0 > 60000) reject(new Error('the build did not load in a minute'));
      else requestAnimationFrame(look);
    };
    look();
  });
}

/** Ready once the current hypothesis has tiles and nothing is loading, after one frame drawn. */
let readyPending = false;
function markReady() {
  const c = cities[api.current];
  const loaded = (o) => o && o.models.size > 0 && o.tiles.loadProgress === 1;
  if (api.ready || readyPending || !loaded(c) || (split && !loaded(cities[partner()]))) return;
  readyPending = true;
  requestAnimationFrame(() => {
    readyPending = false;
    if (c !== cities[api.current] || c.tiles.loadProgress < 1) return;
    render();
    api.tiles = c.models.size;
    status.textContent = `${api.hypotheses[api.current].name}: ${c.models.size} tile(s)`;
    api.ready = true;
  });
}

async function loadLinks(k, c) {
  const base = api.hypotheses[k].base;
  const links = await (await fetch(`${base}links.json`)).json();
  const group = new THREE.Group();
  group.name = 'links';
  for (const l of links) {
    const marker = new THREE.Mesh(
      new THREE.OctahedronGeometry(2.5),
      new THREE.MeshStandardMaterial({ color: 0xd23a2a, emissive: 0x551010 }),
    );
    marker.position.set(l.x, l.z + 12, -l.y);
    marker.userData.link = l;
    const pole = new THREE.Mesh(
      new THREE.CylinderGeometry(0.15, 0.15, 10),
      new THREE.MeshStandardMaterial({ color: 0x553322 }),
    );
    pole.position.set(l.x, l.z + 5, -l.y);
    pole.userData.link = l;
    group.add(marker, pole);
  }
  c.links = group;
  group.visible = k === api.current || split;
  scene.add(group);
}

function show(k) {
  k = ((Number(k) % api.hypotheses.length) + api.hypotheses.length) % api.hypotheses.length;
  api.current = k;
  api.ready = false;
  const c = city(k);
  cities.forEach((o, i) => {
    if (!o) return;
    o.tiles.group.visible = i === k || (split && i === partner());
    if (o.links) o.links.visible = o.tiles.group.visible;
  });
  document.getElementById('hname').textContent = `${k}: ${api.hypotheses[k].name}`;
  const url = new URL(location.href);
  url.searchParams.set('h', k);
  history.replaceState(null, '', url);
  api.tiles = c.models.size;
  if (c.loaded) markReady();
  return k;
}

function partner() {
  return (api.current + 1) % api.hypotheses.length;
}

function setSplit(on) {
  split = on && api.hypotheses.length > 1;
  api.ready = false;
  document.getElementById('split').checked = split;
  document.getElementById('divider').style.display = split ? 'block' : 'none';
  if (split) city(partner());
  show(api.current);
}

/** The scene point of map metres (east, north from the origin; up). */
function point(east, north, up) {
  return new THREE.Vector3(east, up, -north);
}

function lookAt(east, north, up = 0, height = 60) {
  // Not ready until the tiles of the new view are in (the animation loop marks it again):
  // a caller that waits for `ready` after moving must not see the old view's flag.
  api.ready = false;
  const p = point(east, north, up);
  camera.position.set(p.x, p.y + height, p.z + height * 0.02);
  controls.target.copy(p);
  controls.update();
  render();
}

/** A view of a point from 18 m away at 45 degrees azimuth, 8 m above it. */
function lookFrom(east, north, up = 0) {
  api.ready = false;
  const p = point(east, north, up);
  camera.position.set(p.x + 13, p.y + 8, p.z + 13);
  controls.target.copy(p);
  controls.update();
  render();
}

function screenOf(east, north, up) {
  const v = point(east, north, up).project(camera);
  const r = renderer.domElement.getBoundingClientRect();
  return { x: r.left + ((v.x + 1) / 2) * r.width, y: r.top + ((1 - v.y) / 2) * r.height };
}

/** Pixel statistics of the current picture, for tests: drawn, roof grey, plaster white, a hash. */
function sample() {
  render();
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  // The clear colour as drawn (sRGB bytes of the hex).
  const [sr, sg, sb] = [(SKY >> 16) & 255, (SKY >> 8) & 255, SKY & 255];
  let drawn = 0;
  let grey = 0;
  let white = 0;
  let hash = 2166136261;
  for (let i = 0; i < px.length; i += 4) {
    const [r, g, b] = [px[i], px[i + 1], px[i + 2]];
    hash = Math.imul(hash ^ (r ^ (g << 8) ^ (b << 16)), 16777619) >>> 0;
    if (Math.abs(r - sr) + Math.abs(g - sg) + Math.abs(b - sb) < 12) continue;
    drawn += 1;
    const spread = Math.max(r, g, b) - Math.min(r, g, b);
    if (spread < 18 && r > 45 && r < 150) grey += 1;
    // Lime plaster (shikkui) as lit: warm off-white.
    if (Math.min(r, g, b) > 150 && spread < 50) white += 1;
  }
  return { pixels: w * h, drawn, grey, white, hash };
}

function render() {
  const w = window.innerWidth;
  const h = window.innerHeight;
  camera.updateMatrixWorld();
  const visible = cities.map((c) => c && c.tiles.group.visible);
  for (const c of cities) if (c && c.tiles.group.visible) c.tiles.update();
  if (!split) {
    renderer.setScissorTest(false);
    renderer.setViewport(0, 0, w, h);
    renderer.render(scene, camera);
    return;
  }
  // Left half: the current hypothesis; right half: the next one.
  const sides = [api.current, partner()];
  renderer.setScissorTest(true);
  sides.forEach((k, side) => {
    cities.forEach((c, i) => {
      if (!c) return;
      c.tiles.group.visible = i === k;
      if (c.links) c.links.visible = i === k;
    });
    renderer.setScissor(side * (w / 2), 0, w / 2, h);
    renderer.setViewport(0, 0, w, h);
    renderer.render(scene, camera);
  });
  cities.forEach((c, i) => {
    if (c) c.tiles.group.visible = visible[i];
  });
  renderer.setScissorTest(false);
}

// Walking: eye height above the ground (the tiles' ground and streets, else the city's
// zero), W/S or arrows forward and back, A/D turn.
const keys = new Set();
const down = new THREE.Raycaster();
/** The ground's height under (x, z) in the viewer's frame, or null off the loaded ground. */
function groundAt(position) {
  const c = cities[api.current];
  const meshes = c ? [...c.grounds.values()].flat() : [];
  if (!meshes.length) return null;
  down.set(new THREE.Vector3(position.x, 10000, position.z), new THREE.Vector3(0, -1, 0));
  const hit = down.intersectObjects(meshes, false)[0];
  return hit ? hit.point.y : null;
}
function walkStep(dt) {
  if (!walking) return;
  const dir = new THREE.Vector3();
  camera.getWorldDirection(dir);
  dir.y = 0;
  dir.normalize();
  const speed = 6 * dt;
  if (keys.has('w') || keys.has('arrowup')) camera.position.addScaledVector(dir, speed);
  if (keys.has('s') || keys.has('arrowdown')) camera.position.addScaledVector(dir, -speed);
  const turn = (keys.has('a') || keys.has('arrowleft') ? 1 : 0) - (keys.has('d') || keys.has('arrowright') ? 1 : 0);
  if (turn) camera.rotateOnWorldAxis(new THREE.Vector3(0, 1, 0), turn * 1.5 * dt);
  camera.position.y = (groundAt(camera.position) ?? 0) + EYE;
}

function toggleWalk() {
  walking = !walking;
  controls.enabled = !walking;
  if (walking) {
    const t = controls.target.clone();
    camera.position.set(t.x, 0, t.z + 20);
    camera.position.y = (groundAt(camera.position) ?? 0) + EYE;
    camera.lookAt(t.x, camera.position.y, t.z);
  } else {
    controls.target.set(camera.position.x, 0, camera.position.z - 40);
    camera.position.y = 120;
    controls.update();
  }
  document.getElementById('walk').textContent = walking ? 'orbit (K)' : 'walk (K)';
}

function pick(event) {
  const r = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - r.left) / r.width) * 2 - 1, -((event.clientY - r.top) / r.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, camera);
  const c = cities[split && event.clientX > r.left + r.width / 2 ? partner() : api.current];
  const targets = [c.tiles.group];
  if (c.links) targets.push(c.links);
  const shown = (o) => {
    for (; o; o = o.parent) if (!o.visible) return false;
    return true;
  };
  const hit = ray.intersectObjects(targets, true).find((h) => shown(h.object));
  const info = document.getElementById('info');
  if (!hit) {
    info.textContent = '';
    api.info = null;
    return;
  }
  const link = hit.object.userData.link;
  if (link) {
    api.info = { link: link.title, url: link.url };
    info.innerHTML = '';
    const a = document.createElement('a');
    a.href = link.url || link.image;
    a.target = '_blank';
    a.textContent = link.title || a.href;
    info.appendChild(a);
    if (api.openLinks) window.open(a.href, '_blank', 'noopener');
    return;
  }
  const features = hit.object.userData.meshFeatures;
  // An instanced mesh made by three.js' loader has no metadata of its own: the tile's
  // (its scene's) table serves.
  let metadata = null;
  for (let o = hit.object; o && !metadata; o = o.parent) metadata = o.userData.structuralMetadata || null;
  // An instanced tree (EXT_mesh_gpu_instancing): its row is its instance's feature id
  // (EXT_instance_features; three.js keeps the instance attribute on the geometry).
  const instanceIds = hit.object.isInstancedMesh && hit.object.geometry.getAttribute('_FEATURE_ID_0');
  // A walker: a joint (bone) of its tile's skinned crowd, found from the hit vertex's joint;
  // its person and group from the joint node's extras.
  let walker = null;
  if (hit.object.isSkinnedMesh && hit.face) {
    const joints = hit.object.geometry.getAttribute('skinIndex');
    const bone = joints && hit.object.skeleton.bones[joints.getX(hit.face.a)];
    if (bone && bone.userData.person !== undefined) walker = bone.userData;
  }
  api.picked = {
    instance: hit.object.isInstancedMesh ? hit.instanceId : null,
    person: walker ? walker.person : null,
  };
  if (!metadata || (!features && !instanceIds)) return;
  const rows = instanceIds
    ? metadata.getPropertyTableData([0], [instanceIds.getX(hit.instanceId)])
    : metadata.getPropertyTableData(
        features.getFeatureInfo().map((f) => f.propertyTable),
        features.getFeatures(hit.faceIndex, hit.barycoord),
      );
  const row = { ...(rows[0] || {}) };
  if (walker) Object.assign(row, { person: walker.person, group: walker.group });
  api.info = row;
  info.textContent = Object.entries(row)
    .filter(([, v]) => v !== '' && v !== null && v !== undefined)
    .map(([k, v]) => `${k}: ${v}`)
    .join('\n');
  workbench.pick(row);
  offerDesign(row.lot);
  if (row.kind === 'streets' || row.kind === 'ground') showLambdas(hit.point);
}

/** Under the info of a clicked street: its crowd's lambda1-3 over the clip (report.json's
 * crowds of a `people.motion = "boids"` build), `window.edoCity.chart`. */
const reports = new Map();
async function showLambdas(p) {
  const k = api.current;
  if (!reports.has(k)) {
    const base = api.hypotheses[k].base;
    reports.set(k, fetch(`${base}report.json`).then((r) => (r.ok ? r.json() : null)).catch(() => null));
  }
  const report = await reports.get(k);
  const streets = report && report.crowds && report.crowds.streets;
  if (!streets) return;
  // The scene is in the first build's frame: metres from its origin.
  const [oe, on] = sceneOrigin;
  const s = nearestStretch(streets, p.x + oe, -p.z + on);
  api.chart = s ? { street: s.street, series: s.series } : null;
  if (!s) return;
  const info = document.getElementById('info');
  info.append('\n');
  info.appendChild(lambdaChart(s, crowd.api.time));
}

/** A "design this garden" button under the info of a lot that has a garden to design. */
async function offerDesign(lot) {
  if (lot === undefined || lot === null || lot === '') return;
  const list = await api.garden.list().catch(() => null);
  const g = list && list.gardens.find((x) => x.lot === String(lot) || x.lot_id === String(lot));
  if (!g || api.info === null || api.info.lot !== lot) return;
  const b = document.createElement('button');
  b.id = 'design';
  b.textContent = `design this garden (${g.lot})`;
  b.onclick = () => api.garden.open(g.lot).catch((e) => console.warn(e.message));
  document.getElementById('info').append('\n', b);
}

async function main() {
  const list = await (await fetch('/hypotheses.json')).json();
  api.hypotheses = list;
  const first = await (await fetch(list[0].tileset)).json();
  placement = placementOf(first);
  sceneOrigin = (first.extras && first.extras.origin) || [0, 0];
  // Frame the whole city: the root box's centre and size, in the scene.
  const b = first.root.boundingVolume.box;
  const centre = new THREE.Vector3(b[0], b[2], -b[1]);
  const radius = Math.max(Math.hypot(b[3], b[4], b[5]), Math.hypot(b[6], b[7], b[8]), 50);
  camera.position.set(centre.x + radius * 0.55, centre.y + radius * 0.75, centre.z + radius * 0.8);
  controls.target.copy(centre);
  controls.update();
  const asked = Number(params.get('h') ?? 0);
  show(Number.isFinite(asked) ? asked : 0);
  if (params.get('split') === '1') setSplit(true);

  document.getElementById('prev').onclick = () => show(api.current - 1);
  document.getElementById('next').onclick = () => show(api.current + 1);
  document.getElementById('split').onchange = (e) => setSplit(e.target.checked);
  document.getElementById('walk').onclick = toggleWalk;
  const playButton = document.getElementById('crowd');
  const showPlaying = () => {
    playButton.textContent = crowd.api.playing ? 'pause crowd (P)' : 'play crowd (P)';
  };
  playButton.onclick = () => {
    crowd.api.play();
    showPlaying();
  };
  showPlaying();
  for (const box of document.querySelectorAll('#toggles input')) {
    box.onchange = () => {
      for (const k of box.dataset.kinds.split(',')) {
        if (box.checked) hidden.delete(k);
        else hidden.add(k);
      }
      for (const c of cities) if (c) applyToggles(c.tiles.group);
      render();
    };
  }
  renderer.domElement.addEventListener('click', pick);
  workbench.start().catch((e) => console.warn('workbench', e));
  window.addEventListener('keydown', (e) => {
    // Typing in the workbench's fields is not steering the view.
    if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
    const k = e.key.toLowerCase();
    if (k === ']' || k === 'h') show(api.current + 1);
    else if (k === '[') show(api.current - 1);
    else if (k === 'k') toggleWalk();
    else if (k === 'p') playButton.click();
    else if (k === 's' && !walking) setSplit(!split);
    else keys.add(k);
  });
  window.addEventListener('keyup', (e) => keys.delete(e.key.toLowerCase()));
  window.addEventListener('resize', () => {
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(window.innerWidth, window.innerHeight);
    for (const c of cities) if (c) c.tiles.setResolutionFromRenderer(camera, renderer);
  });
  let last = performance.now();
  const frames = [];
  renderer.setAnimationLoop((now) => {
    walkStep(Math.min((now - last) / 1000, 0.1));
    crowd.advance(Math.min((now - last) / 1000, 0.1));
    last = now;
    if (!walking) controls.update();
    renderer.info.reset();
    render();
    countFrame(now, frames);
    markReady();
  });
}

/** The stats of the frame just drawn. */
function countFrame(now, frames) {
  const st = api.stats;
  st.drawCalls = renderer.info.render.calls;
  st.triangles = renderer.info.render.triangles;
  const c = cities[api.current];
  st.tilesLoaded = c ? c.models.size : 0;
  frames.push(now);
  // The last second's frames, and at least the last two (a frame may take longer).
  while (frames.length > 2 && frames[0] < now - 1000) frames.shift();
  st.fps = frames.length > 1 ? ((frames.length - 1) * 1000) / (now - frames[0]) : 0;
}

main().catch((e) => {
  status.textContent = `error: ${e.message}`;
  console.error(e);
});
