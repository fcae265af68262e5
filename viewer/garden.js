// The rock-garden designer (issue 42): a visitor designs a temple's garden by the interactive
// GA of seed 000, in its place in the city. The GA runs on the server (`edo-city serve`,
// /api/gardens...); this module shows each generation's candidates, drawn from the garden's
// viewpoint (its hall's veranda), with their five rule scores and fitness, shows one of them
// in place in the precinct, sends the visitor's picks, and keeps the chosen design.
//
// window.edoCity.garden = { open(lot), lot, generation, candidates, pick(indices), next(),
// undo(), keep(), choose(), place(k), close(), list(), picks, session, writable, timings }.
import * as THREE from 'three';

const RULES = ['centre', 'triangles', 'opposition', 'adjacency', 'axis'];
const THUMB = { w: 220, h: 130 };
const EYE = 1.2; // seated on the veranda

/**
 * The designer. `ctx` gives what it needs of the viewer: the scene, `point(east, north, up)`
 * into it, `render()`, `build()` (the current build's index), `hideStones(hidden)` (the
 * tiles' own stones, while a candidate stands in their place) and `frame(east, north, up)`
 * (a view of the garden).
 */
export function createDesigner(ctx) {
  const panel = document.getElementById('designer');
  const cards = document.getElementById('dcards');
  const title = document.getElementById('dtitle');
  const message = document.getElementById('dmessage');
  let gardens = null; // the list of the current build, from GET /api/gardens
  let listed = -1; // the build it is of
  let garden = null; // the one being designed (its list entry)
  let state = null; // the server's answer: session, generation, candidates, ...
  let picks = new Set();
  let shown = 0; // the candidate standing in the precinct
  const inPlace = new THREE.Group();
  inPlace.name = 'designer-stones';
  ctx.scene.add(inPlace);
  const thumbs = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  thumbs.setSize(THUMB.w, THUMB.h);
  thumbs.setClearColor(0x9c8f7a); // the earthen wall behind a garden

  const api = {
    get lot() { return garden ? garden.lot : null; },
    get generation() { return state ? state.generation : null; },
    get candidates() { return state ? state.candidates : []; },
    get session() { return state ? state.session : null; },
    get picks() { return [...picks].sort((a, b) => a - b); },
    get shown() { return shown; },
    get writable() { return gardens ? gardens.writable : false; },
    timings: [],
    kept: null,
    error: null,
    list,
    open,
    pick,
    next: () => next(api.picks),
    choose: () => next([]),
    undo,
    keep,
    place,
    close,
  };

  const quiet = (f) => () => f().catch((e) => console.warn(e.message));
  document.getElementById('dnext').onclick = quiet(api.next);
  document.getElementById('dchoose').onclick = quiet(api.choose);
  document.getElementById('dundo').onclick = quiet(undo);
  document.getElementById('dkeep').onclick = quiet(() => keep());
  document.getElementById('dclose').onclick = close;

  // The page's token for writes (GET /api/token): the server refuses a POST without it,
  // so another origin's page cannot drive the designer (docs/garden.md).
  let token = null;
  async function call(route, body) {
    if (!token) token = (await (await fetch('/api/token')).json()).token;
    const r = await fetch(`/api/gardens/${route}`, {
      method: 'POST',
      headers: { 'content-type': 'application/json', 'x-edo-city-token': token },
      body: JSON.stringify(body),
    });
    const answer = await r.json();
    if (!r.ok) {
      api.error = answer.error || `HTTP ${r.status}`;
      message.textContent = api.error;
      throw new Error(api.error);
    }
    api.error = null;
    message.textContent = '';
    return answer;
  }

  /** The gardens the current build can design (cached per build). */
  async function list() {
    const h = ctx.build();
    if (listed !== h) {
      gardens = await (await fetch(`/api/gardens?h=${h}`)).json();
      listed = h;
    }
    return gardens;
  }

  /** The garden of a lot id (or garden key), if the build has one. */
  async function find(lot) {
    const l = await list();
    return l.gardens.find((g) => g.lot === String(lot)) || l.gardens.find((g) => g.lot_id === String(lot)) || null;
  }

  async function open(lot, population) {
    const g = await find(lot);
    if (!g) {
      api.error = `no garden to design at lot ${lot}`;
      throw new Error(api.error);
    }
    const body = { lot: g.lot, h: ctx.build() };
    if (population) body.population = population;
    const s = await call('open', body);
    garden = g;
    panel.style.display = 'block';
    ctx.hideStones(true);
    show(s);
    const c = centre(g);
    ctx.frame(c.east, c.north, g.ground, Math.max(g.size[0], g.size[1]));
    return api.generation;
  }

  /** Toggles or sets the picks: `pick([0, 3])` sets them, `pick(2)` toggles one. */
  function pick(indices) {
    if (Array.isArray(indices)) picks = new Set(indices.map(Number));
    else if (picks.has(Number(indices))) picks.delete(Number(indices));
    else picks.add(Number(indices));
    drawCards(false);
    return api.picks;
  }

  async function next(chosen) {
    const t0 = performance.now();
    const s = await call('next', { session: state.session, generation: state.generation, picks: chosen });
    const t1 = performance.now();
    show(s);
    const t2 = performance.now();
    api.timings.push({ generation: s.generation, population: s.population, server_ms: t1 - t0, render_ms: t2 - t1, total_ms: t2 - t0 });
    return s.generation;
  }

  async function undo() {
    show(await call('undo', { session: state.session, generation: state.generation }));
    return state.generation;
  }

  async function keep(k = shown) {
    const r = await call('keep', { session: state.session, generation: state.generation, candidate: k });
    api.kept = r;
    message.textContent = `kept in ${r.file}: rebuild with [garden] designs = "${r.file}"`;
    return r;
  }

  function close() {
    panel.style.display = 'none';
    inPlace.clear();
    ctx.hideStones(false);
    garden = null;
    state = null;
    ctx.render();
  }

  function show(s) {
    state = s;
    picks = new Set();
    shown = 0;
    title.textContent = `garden ${garden.lot}: generation ${s.generation} (${s.population} layouts)`;
    document.getElementById('dundo').disabled = !s.can_undo;
    document.getElementById('dkeep').disabled = !api.writable;
    drawCards(true);
    place(0);
  }

  /** Stands candidate `k` in the precinct. */
  function place(k) {
    shown = Number(k);
    inPlace.clear();
    const c = state.candidates[shown];
    for (const st of c.stones) {
      const m = stoneMesh(st);
      m.rotation.y = garden.angle;
      const p = toMap(garden, st.x, st.y);
      m.position.copy(ctx.point(p.east, p.north, garden.ground + 0.03));
      inPlace.add(m);
    }
    for (const el of cards.querySelectorAll('.dcard')) el.classList.toggle('inplace', Number(el.dataset.k) === shown);
    ctx.render();
    return shown;
  }

  function drawCards(redraw) {
    if (redraw) {
      cards.innerHTML = '';
      state.candidates.forEach((c, k) => cards.appendChild(card(c, k)));
    }
    for (const el of cards.querySelectorAll('.dcard')) el.classList.toggle('picked', picks.has(Number(el.dataset.k)));
  }

  function card(c, k) {
    const el = document.createElement('div');
    el.className = 'dcard';
    el.dataset.k = k;
    const canvas = document.createElement('canvas');
    canvas.width = THUMB.w;
    canvas.height = THUMB.h;
    drawFromViewpoint(c, canvas);
    canvas.title = 'click to pick (again to unpick)';
    canvas.onclick = () => pick(k);
    const text = document.createElement('div');
    text.className = 'dscores';
    // The five degrees of violation (0: the rule is kept), by the rules' first letters.
    text.textContent = `#${k} fitness ${c.fitness.toFixed(3)}\n` + RULES.map((r) => `${r.slice(0, 3)} ${(c.scores[r] ?? 0).toFixed(2)}`).join(' ');
    text.title = RULES.map((r) => `${r}: ${c.scores[r]}`).join('\n');
    const here = document.createElement('button');
    here.textContent = 'in place';
    here.onclick = () => place(k);
    el.append(canvas, text, here);
    return el;
  }

  // One scene for every picture: lights, the gravel (resized per garden) and a pool of
  // stones sharing one geometry and three materials (new meshes per picture made each
  // generation take a second in a software-rendered browser).
  const thumbScene = new THREE.Scene();
  thumbScene.add(new THREE.HemisphereLight(0xffffff, 0x8a7f6a, 2.4));
  const thumbSun = new THREE.DirectionalLight(0xffffff, 1.4);
  thumbSun.position.set(0.3, 1, -0.5);
  thumbScene.add(thumbSun);
  const gravel = new THREE.Mesh(new THREE.PlaneGeometry(1, 1), new THREE.MeshStandardMaterial({ color: 0xd9d4c7 }));
  gravel.rotation.x = -Math.PI / 2;
  thumbScene.add(gravel);
  const pool = [];
  const thumbCamera = new THREE.PerspectiveCamera(50, THUMB.w / THUMB.h, 0.1, 500);

  /** A candidate seen from the garden's viewpoint, into `canvas`. */
  function drawFromViewpoint(c, canvas) {
    const [w, d] = state.size;
    // Garden frame: x along the viewing side, y away from it -> scene x, -z.
    gravel.scale.set(w, d, 1);
    gravel.position.set(w / 2, 0, -d / 2);
    while (pool.length < c.stones.length) {
      const m = new THREE.Mesh(UNIT_STONE, STONE_MATERIALS.other);
      pool.push(m);
      thumbScene.add(m);
    }
    pool.forEach((m, k) => {
      const st = c.stones[k];
      m.visible = st !== undefined;
      if (!st) return;
      placeStone(m, st);
      m.position.set(st.x, 0, -st.y);
    });
    // From the veranda, raised so that every group shows: the eye plus 0.6 of the garden's
    // depth (a seated visitor sees Ryoanji from ~1.2 m; a picture the size of a card needs
    // the stones apart).
    const [vx, vy] = state.viewpoint;
    thumbCamera.position.set(vx, EYE + 0.6 * d, -vy);
    thumbCamera.lookAt(w / 2, 0, -d * 0.5);
    thumbs.render(thumbScene, thumbCamera);
    canvas.getContext('2d').drawImage(thumbs.domElement, 0, 0);
  }

  return api;
}

/** The stones' shape: a faceted block of diameter 1, its base at 0 (scaled per stone). */
const UNIT_STONE = new THREE.DodecahedronGeometry(0.5, 0).translate(0, 0.5, 0);
/** Shin darkest, as the eye picks the master stone of a group. */
const STONE_MATERIALS = {
  shin: new THREE.MeshStandardMaterial({ color: 0x5d5a55, flatShading: true }),
  soe: new THREE.MeshStandardMaterial({ color: 0x6e6a63, flatShading: true }),
  other: new THREE.MeshStandardMaterial({ color: 0x7d786f, flatShading: true }),
};

/** Sizes and shades `m` as stone `st`: its plan `size` across, flattened as the tiles' are. */
function placeStone(m, st) {
  m.scale.set(st.size, st.size * 0.7, st.size);
  m.material = STONE_MATERIALS[st.role] ?? STONE_MATERIALS.other;
}

/** A stone of its own (the one standing in the precinct). */
function stoneMesh(st) {
  const m = new THREE.Mesh(UNIT_STONE, STONE_MATERIALS.other);
  placeStone(m, st);
  return m;
}

/** Map metres from the origin of garden point (x, y). */
function toMap(g, x, y) {
  const [s, c] = [Math.sin(g.angle), Math.cos(g.angle)];
  return { east: g.corner[0] + x * c - y * s, north: g.corner[1] + x * s + y * c };
}

function centre(g) {
  return toMap(g, g.size[0] / 2, g.size[1] / 2);
}
