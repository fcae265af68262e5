// The street crowds (people.motion = "boids"): a GLB tile with walkers carries one looping
// glTF clip, "crowd", of every walker's translation and rotation. Every tile's clip is set
// to the same time, one clock for the whole city, so walkers that cross from one tile into
// the next stay in step with their neighbours. window.edoCity.crowd = { playing, time,
// duration, walkers, play(on), setTime(t) }; the panel's button and the P key play or pause.
import * as THREE from 'three';

export const CLIP = 'crowd';

export function createCrowd() {
  const tiles = new Map(); // tile -> { mixer, clip, walkers }
  const state = { playing: true, time: 0 };

  const duration = () => Math.max(0, ...[...tiles.values()].map((t) => t.clip.duration));
  const apply = () => {
    for (const { mixer, clip } of tiles.values()) mixer.setTime(state.time % clip.duration);
  };

  const api = {
    get playing() {
      return state.playing;
    },
    get time() {
      return state.time;
    },
    /** The longest clip loaded (every build's clip is `crowd.duration` long). */
    get duration() {
      return duration();
    },
    /** Walkers in the tiles loaded now. */
    get walkers() {
      let n = 0;
      for (const t of tiles.values()) n += t.walkers;
      return n;
    },
    play(on = !state.playing) {
      state.playing = Boolean(on);
      return state.playing;
    },
    /** Puts every walker where it is `t` seconds into the clip (looping). */
    setTime(t) {
      const d = duration();
      state.time = d > 0 ? ((Number(t) % d) + d) % d : 0;
      apply();
      return state.time;
    },
  };

  /** A tile was loaded: plays its clip, if it has one, from the city's time. */
  function add(tile, model, clips) {
    const clip = (clips || []).find((c) => c.name === CLIP);
    if (!clip || !(clip.duration > 0)) return;
    const mixer = new THREE.AnimationMixer(model);
    mixer.clipAction(clip).play();
    let walkers = 0;
    model.traverse((o) => {
      if (o.userData.person !== undefined) walkers += 1;
    });
    tiles.set(tile, { mixer, clip, walkers });
    mixer.setTime(state.time % clip.duration);
  }

  function remove(tile) {
    const t = tiles.get(tile);
    if (!t) return;
    t.mixer.stopAllAction();
    t.mixer.uncacheRoot(t.mixer.getRoot());
    tiles.delete(tile);
  }

  /** The frame's step: `dt` seconds on while playing. */
  function advance(dt) {
    if (!state.playing || tiles.size === 0) return;
    const d = duration();
    state.time = (state.time + dt) % d;
    apply();
  }

  return { api, add, remove, advance };
}

/** The stretch of `streets` (report.json's crowds.streets, ends in map metres) nearest the map
 * point (east, north), within `reach` metres, or null. */
export function nearestStretch(streets, east, north, reach = 30) {
  let best = null;
  let bestD = reach;
  for (const s of streets || []) {
    const [[ax, ay], [bx, by]] = s.line || [[0, 0], [0, 0]];
    const dx = bx - ax;
    const dy = by - ay;
    const len2 = dx * dx + dy * dy;
    const t = len2 > 0 ? Math.max(0, Math.min(1, ((east - ax) * dx + (north - ay) * dy) / len2)) : 0;
    const d = Math.hypot(ax + t * dx - east, ay + t * dy - north);
    if (d < bestD) {
      bestD = d;
      best = s;
    }
  }
  return best;
}

/** A small chart of a stretch's lambda1-3 over the clip (one value a second), with the
 * crowd's time marked: a canvas for the info panel. */
export function lambdaChart(stretch, time) {
  const w = 228;
  const h = 110;
  const canvas = document.createElement('canvas');
  canvas.id = 'lambdas';
  canvas.width = w;
  canvas.height = h;
  const g = canvas.getContext('2d');
  const series = stretch.series || [];
  const pad = { l: 26, r: 6, t: 14, b: 14 };
  const x = (i) => pad.l + ((w - pad.l - pad.r) * i) / Math.max(1, series.length - 1);
  // lambda1 and lambda3 are from -1 to 1, lambda2 from 0 to 1.
  const y = (v) => pad.t + ((h - pad.t - pad.b) * (1 - v)) / 2;
  g.fillStyle = '#fff';
  g.fillRect(0, 0, w, h);
  g.strokeStyle = '#ccc';
  g.font = '10px sans-serif';
  g.fillStyle = '#555';
  for (const v of [-1, 0, 1]) {
    g.beginPath();
    g.moveTo(pad.l, y(v));
    g.lineTo(w - pad.r, y(v));
    g.stroke();
    g.fillText(String(v), 4, y(v) + 3);
  }
  const colours = ['#c0392b', '#2471a3', '#229954'];
  colours.forEach((c, k) => {
    g.strokeStyle = c;
    g.beginPath();
    series.forEach((s, i) => (i ? g.lineTo(x(i), y(s[k])) : g.moveTo(x(i), y(s[k]))));
    g.stroke();
    g.fillStyle = c;
    g.fillText(`λ${k + 1}`, pad.l + 4 + 26 * k, 10);
  });
  g.fillStyle = '#555';
  g.fillText(`${stretch.street}, ${series.length} s`, pad.l + 84, 10);
  if (series.length > 1 && time !== undefined) {
    const t = x(Math.min(series.length - 1, time));
    g.strokeStyle = '#000';
    g.beginPath();
    g.moveTo(t, pad.t);
    g.lineTo(t, h - pad.b);
    g.stroke();
  }
  return canvas;
}
