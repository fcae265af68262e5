// The workbench (issue 61): with `edo-city serve OUT --edit PARAMS.toml` a panel lists every
// parameter by section (search box, the changed ones marked), a clicked lot can be given
// another type, use, district or number of storeys, and each change rebuilds the first build
// on the server, keeping the tiles that stay the same; the viewer then loads the build
// again (the tiles that did not change answer 304 from the browser's cache) and outlines
// the lots that changed. Undo, redo, reroll (a new seed) and save (the parameter file, its
// overrides and its log beside it) are buttons and calls:
//
// window.edoCity.edit = { enabled, params(), set(key, value), lot(id, field, value), undo(),
//   redo(), save(), reroll(), lock(section, keep), status, changedLots, compare(h) }
//
// `lock` keeps a section's draw (the machiya's types and forms, the trees, the people, the
// gardens: `[seeds]`) while `reroll` draws the rest again.
//
// The outlines show the lots the last rebuild changed, or (`compare(h)`, the panel's
// "outline against") those where another served build and the hypothesis disagree.
//
// `set`, `lot`, `undo`, `redo` and `reroll` return a Promise that resolves when the changed
// tiles are shown (with the server's answer) and rejects with the build's message.
// `status` is { busy, revision, changedTiles, lastMs, error }, polled, so a second page sees
// a revision another one made.
import * as THREE from 'three';

const OUTLINE = 0xff5a1f;
const TILE_BOX = 0xffc04d;

/** The workbench over the viewer's `reload(rev)` (resolves once the first build is shown
 * again) and `point(east, north, up)`. */
export function createWorkbench({ scene, point, render, reload, base }) {
  const panel = document.getElementById('workbench');
  const outlines = new THREE.Group();
  outlines.name = 'changed lots';
  scene.add(outlines);
  let token = null;
  let shown = 0; // the revision the viewer shows
  let list = []; // the parameters, as last fetched
  let state = null;
  let picked = null;

  // Each tile's revision of its last change, in its URL (`?v=`): the browser's cache is
  // then never asked whether a tile rewritten within the second it was fetched changed
  // (its Last-Modified has whole seconds). The levels of detail above change with any tile
  // below them: theirs carry the revision shown.
  const versions = new Map();
  // A plugin of its own for each TilesRenderer (one may not be shared).
  const urls = () => ({
    name: 'EDO_CITY_REVISIONS',
    preprocessURL(url) {
      if (!shown) return url;
      const u = new URL(url, location.href);
      const id = (u.pathname.match(/\/tiles\/([^/]+)\.glb$/) || [])[1];
      const v = u.pathname.includes('/tiles/lod/') ? shown : versions.get(id);
      if (v === undefined) return url;
      u.searchParams.set('v', v);
      return u.toString();
    },
  });

  const edit = {
    enabled: false,
    status: { busy: false, revision: 0, changedTiles: [], lastMs: 0, error: null },
    changedLots: [],
    /** The revision the viewer shows. */
    get shown() {
      return shown;
    },
    params: () => fetchParams(),
    set: (key, value) => write('set', { key, value }),
    lot: (id, field, value) => write('lot', { lot: String(id), field, value: String(value) }),
    undo: () => write('undo', {}),
    redo: () => write('redo', {}),
    reroll: () => write('reroll', {}),
    /** Keeps `section`'s draw (machiya, trees, people, gardens) through rerolls, or not. */
    lock: (section, keep) => write('lock', { section, keep: Boolean(keep) }),
    /** Outlines the lots where served build `h` and the hypothesis disagree (null: those
     * the last rebuild changed); resolves with them. */
    compare: (h) => {
      against = h === null || h === undefined ? null : Number(h);
      const locks = document.getElementById('wlocks');
    for (const section of state.seedSections) {
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.value = section;
      box.checked = state.locks.includes(section);
      box.onchange = () => edit.lock(section, box.checked).catch(() => showLocks());
      label.append(box, ` ${section}`);
      locks.appendChild(label);
    }
    const select = document.getElementById('wagainst');
      if (select) select.value = against === null ? '' : String(against);
      return outline(edit.status);
    },
    save: async () => {
      const answer = await post('save', {});
      await poll();
      return answer;
    },
  };

  async function fetchParams() {
    const r = await fetch('/api/params');
    list = await r.json();
    return list;
  }

  /** The page's token for writes (GET /api/token). */
  async function pageToken() {
    if (!token) token = (await (await fetch('/api/token')).json()).token;
    return token;
  }

  async function post(route, body) {
    const send = async () => fetch(`/api/edit/${route}`, {
      method: 'POST',
      headers: { 'content-type': 'application/json', 'x-edo-city-token': await pageToken() },
      body: JSON.stringify(body),
    });
    let r = await send();
    let answer = await r.json();
    // A token the server no longer takes (it was started again since this page loaded):
    // a new one, and the edit sent once more. Nothing was done with the refused request.
    if (r.status === 403 && /token/.test(answer.error || '')) {
      token = null;
      r = await send();
      answer = await r.json();
    }
    if (!r.ok) {
      edit.status = { ...edit.status, error: answer.error };
      showStatus();
      throw new Error(answer.error);
    }
    return answer;
  }

  /** An edit: posted with the revision this page saw, built, then shown. */
  async function write(route, body) {
    edit.status = { ...edit.status, busy: true };
    showStatus();
    const answer = await post(route, { ...body, base: edit.status.requested });
    await poll();
    while (edit.status.busy || edit.status.revision < answer.revision) {
      await new Promise((r) => setTimeout(r, 250));
      await poll();
    }
    await showRevision();
    await fetchParams();
    drawPanel();
    await showLocks();
    return answer;
  }

  /** The server's status; a newer revision (this page's or another's) is loaded. */
  async function poll() {
    const s = await (await fetch('/api/edit/status')).json();
    edit.status = s;
    showStatus();
    return s;
  }

  /** The revision the server built, shown (once, however many callers ask). */
  let showing = Promise.resolve();
  function showRevision() {
    const s = edit.status;
    if (s.revision === shown) return showing;
    shown = s.revision;
    for (const id of s.changedTiles) versions.set(id, s.revision);
    showing = (async () => {
      await reload(s.revision);
      await outline(s);
    })();
    return showing;
  }

  /** The lots outlined: those the last rebuild changed, or, against a served build, those
   * where it and the hypothesis disagree. */
  let against = null;
  async function outline(s) {
    const lots = against === null
      ? s.changedLots || []
      : (await (await fetch(`/api/edit/compare?h=${against}`)).json()).changedLots || [];
    edit.changedLots = lots;
    await drawOutlines(lots, against === null ? s.changedTiles : []);
    render();
    return lots;
  }

  /** Each lot outlined at the ground and at eave height; each tile of `tiles` boxed. */
  async function drawOutlines(lots, tiles) {
    for (const o of [...outlines.children]) {
      outlines.remove(o);
      o.geometry.dispose();
    }
    const line = new THREE.LineBasicMaterial({ color: OUTLINE, depthTest: false, transparent: true });
    for (const l of lots) {
      for (const up of [0.4, 9]) {
        const pts = l.ring.map(([e, n]) => point(e, n, up));
        const loop = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(pts), line);
        loop.renderOrder = 10;
        loop.userData.lot = l.lot;
        outlines.add(loop);
      }
    }
    const manifest = await (await fetch(`${base}manifest.json`)).json().catch(() => null);
    if (!manifest) return;
    const box = new THREE.LineBasicMaterial({ color: TILE_BOX, transparent: true, opacity: 0.6 });
    for (const t of manifest.tiles) {
      if (!tiles.includes(t.id) || !t.bounds) continue;
      const [e0, n0, u0, e1, n1, u1] = t.bounds;
      const b = new THREE.Box3().setFromPoints([point(e0, n0, u0), point(e1, n1, u1)]);
      const helper = new THREE.Box3Helper(b, TILE_BOX);
      helper.material = box;
      outlines.add(helper);
    }
  }

  function showStatus() {
    const el = document.getElementById('wstatus');
    if (!el) return;
    const s = edit.status;
    const saved = s.saved === false ? ' · not saved' : '';
    el.textContent = s.error
      ? `error: ${s.error}`
      : s.busy
        ? 'rebuilding…'
        : `revision ${s.revision}: ${s.changedTiles.length} tile(s) rebuilt in ${(s.lastMs / 1000).toFixed(1)} s${saved}`
          + (s.notice ? ` · ${s.notice}` : '');
    el.classList.toggle('error', Boolean(s.error));
  }

  /** One row of the panel: the key, an input by its type and what it allows, reset. */
  function row(p) {
    const div = document.createElement('div');
    div.className = 'wparam';
    const changed = JSON.stringify(p.value) !== JSON.stringify(p.default);
    div.classList.toggle('changed', changed);
    div.title = p.doc;
    div.dataset.key = p.key;
    const label = document.createElement('label');
    label.textContent = p.key.slice(p.section === 'general' ? 0 : p.section.length + 1);
    div.appendChild(label);
    let input;
    const a = p.allowed || {};
    if (a.values) {
      input = document.createElement('select');
      for (const v of a.values) input.add(new Option(v, v, false, v === p.value));
    } else if (p.type === 'boolean') {
      input = document.createElement('input');
      input.type = 'checkbox';
      input.checked = Boolean(p.value);
    } else if (p.type === 'integer' || p.type === 'float') {
      input = document.createElement('input');
      input.type = 'number';
      input.step = p.type === 'integer' ? '1' : 'any';
      if (a.min !== undefined) input.min = a.min;
      if (a.max !== undefined) input.max = a.max;
      input.value = p.value;
    } else {
      input = document.createElement('input');
      input.value = p.type === 'string' ? p.value : JSON.stringify(p.value);
    }
    input.onchange = () => {
      let v;
      try {
        v = input.type === 'checkbox' ? input.checked
          : input.type === 'number' ? Number(input.value)
          : p.type === 'string' ? input.value : JSON.parse(input.value);
      } catch (e) {
        edit.status = { ...edit.status, error: `${p.key}: ${e.message}` };
        showStatus();
        return;
      }
      edit.set(p.key, v).catch(() => drawPanel());
    };
    div.appendChild(input);
    if (changed) {
      const reset = document.createElement('button');
      reset.textContent = '↺';
      reset.title = `back to the default (${JSON.stringify(p.default)})`;
      reset.onclick = () => edit.set(p.key, null).catch(() => {});
      div.appendChild(reset);
    }
    return div;
  }

  function drawPanel() {
    const body = document.getElementById('wparams');
    const find = document.getElementById('wsearch').value.trim().toLowerCase();
    const open = new Set([...body.querySelectorAll('details[open]')].map((d) => d.dataset.section));
    body.innerHTML = '';
    const sections = new Map();
    for (const p of list) {
      const hit = !find || p.key.toLowerCase().includes(find) || p.doc.toLowerCase().includes(find);
      if (!hit) continue;
      if (!sections.has(p.section)) sections.set(p.section, []);
      sections.get(p.section).push(p);
    }
    for (const [section, params] of sections) {
      const d = document.createElement('details');
      d.dataset.section = section;
      d.open = Boolean(find) || open.has(section);
      const changed = params.filter((p) => JSON.stringify(p.value) !== JSON.stringify(p.default)).length;
      const s = document.createElement('summary');
      s.textContent = changed ? `${section} (${changed} changed)` : section;
      d.appendChild(s);
      for (const p of params) d.appendChild(row(p));
      body.appendChild(d);
    }
    drawLot();
  }

  /** The picked lot's editor: its type, use, district and storeys. */
  function drawLot() {
    const box = document.getElementById('wlot');
    box.innerHTML = '';
    if (!picked || !picked.lot || !state) return;
    const title = document.createElement('div');
    title.className = 'wlottitle';
    title.textContent = `lot ${picked.lot}`;
    box.appendChild(title);
    const field = (name, input, current) => {
      const div = document.createElement('div');
      div.className = 'wparam';
      const label = document.createElement('label');
      label.textContent = name;
      div.append(label, input);
      input.dataset.field = name;
      input.value = current ?? '';
      input.onchange = () => edit.lot(picked.lot, name, input.value).catch(() => {});
      box.appendChild(div);
    };
    const select = (values) => {
      const s = document.createElement('select');
      for (const v of ['', ...values]) s.add(new Option(v || '(drawn)', v));
      return s;
    };
    field('mtype', select(state.types), picked.mtype);
    field('use', select(state.uses), picked.use);
    field('district', document.createElement('input'), picked.district);
    const storeys = document.createElement('input');
    storeys.type = 'number';
    storeys.min = '1';
    storeys.max = '5';
    field('storeys', storeys, '');
  }

  /** The "keep the draw of" boxes as the hypothesis has them (an undo may change them). */
  async function showLocks() {
    const s = await (await fetch('/api/edit/state')).json();
    for (const box of document.querySelectorAll('#wlocks input')) box.checked = s.locks.includes(box.value);
  }

  async function start() {
    const r = await fetch('/api/edit/state');
    state = await r.json();
    if (!r.ok || state.enabled === false) return; // read-only: no --edit
    edit.enabled = true;
    edit.status = state.status;
    // The page may have loaded the build before the server's first rebuild of it ended:
    // the first revision is loaded again whatever it is (unchanged tiles answer 304).
    shown = 0;
    panel.style.display = 'block';
    document.getElementById('wfile').textContent = state.params.split('/').pop();
    document.getElementById('wfile').title = state.params;
    document.getElementById('wsearch').oninput = drawPanel;
    const select = document.getElementById('wagainst');
    const builds = await (await fetch('/hypotheses.json')).json();
    for (const b of builds.slice(1)) select.add(new Option(`build ${b.index}: ${b.name}`, b.index));
    select.onchange = () => edit.compare(select.value === '' ? null : select.value).catch(() => {});
    document.getElementById('wundo').onclick = () => edit.undo().catch(() => {});
    document.getElementById('wredo').onclick = () => edit.redo().catch(() => {});
    document.getElementById('wreroll').onclick = () => edit.reroll().catch(() => {});
    document.getElementById('wsave').onclick = () => edit.save().catch(() => {});
    await fetchParams();
    drawPanel();
    showStatus();
    // Another page's edits, and the first build the server makes on start.
    setInterval(() => {
      if (!edit.status.busy && document.hidden) return;
      poll().then(() => (edit.status.busy ? null : showRevision())).catch(() => {});
    }, 1500);
  }

  return {
    api: edit,
    urls,
    start,
    /** A clicked object's row: its lot becomes the one the lot editor edits. */
    pick: (row) => {
      picked = row && row.lot ? row : picked;
      if (edit.enabled) drawLot();
    },
  };
}
