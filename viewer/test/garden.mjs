// The garden designer in Debian's chromium (headless, SwiftShader), driven by
// playwright-core through window.edoCity.garden (issue 42).
//
//   node test/garden.mjs <url> design <lot> [screenshot-dir]
//     opens the designer on the garden of <lot> by clicking the city there, picks two
//     candidates for three generations (every pick must change the next generation), replays
//     the same picks in a second session (the answers must be the same), keeps the candidate
//     in place, and prints one JSON line: the kept design, the generations, the timings.
//   node test/garden.mjs <url> check <lot> [screenshot-dir]
//     reloads the viewer after a rebuild and prints the garden as the build lists it now.
//   node test/garden.mjs <url> time <lot> <population> <generations>
//     times "next generation" (server + transfer, then drawing the candidates).
//   node test/garden.mjs <url> attack <lot>
//     a page of another origin (a server of its own on another port) tries what a hostile
//     site would: no-cors text/plain POSTs that open a session on <lot> and keep candidates
//     of guessed sessions, reading a page token, a JSON POST with a made-up token. Prints
//     what each attempt got; the caller checks that the designs file did not change.
import { fromElsewhere, launchChromium } from './launch.mjs';

const [url, phase, lot, arg4, arg5] = process.argv.slice(2);
if (!url || !phase || !lot) {
  console.error('usage: node test/garden.mjs <url> design|check|time|attack <lot> ...');
  process.exit(2);
}
if (phase === 'attack') {
  console.log(JSON.stringify(await attack(url, lot)));
  process.exit(0);
}
const problems = [];
const fail = (m) => problems.push(m);

const browser = await launchChromium();
const out = { phase };
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 720 } });
  page.on('console', (m) => {
    if (m.type() === 'error') fail(`console error: ${m.text()}`);
  });
  page.on('pageerror', (e) => fail(`page error: ${e.message}`));
  page.on('response', (r) => {
    if (r.status() >= 400) fail(`HTTP ${r.status()}: ${r.url()}`);
  });
  page.setDefaultTimeout(120000);
  await page.goto(`${url}?h=0`, { waitUntil: 'domcontentloaded', timeout: 120000 });
  await page.waitForFunction(() => window.edoCity && window.edoCity.ready, null, { timeout: 120000 });
  const list = await page.evaluate(() => window.edoCity.garden.list());
  const garden = list.gardens.find((g) => g.lot === lot || g.lot_id === lot);
  if (!garden) throw new Error(`no garden at lot ${lot} in ${JSON.stringify(list)}`);
  out.garden = garden;

  if (phase === 'design') {
    // A visitor's way in: click the gravel in the city, then "design this garden".
    const [s, c] = [Math.sin(garden.angle), Math.cos(garden.angle)];
    const [x, y] = [garden.size[0] * 0.5, garden.size[1] * 0.08];
    const east = garden.corner[0] + x * c - y * s;
    const north = garden.corner[1] + x * s + y * c;
    await page.evaluate(([e, n, u]) => window.edoCity.lookAt(e, n, u, 40), [east, north, garden.ground]);
    await page.waitForFunction(() => window.edoCity.ready);
    const at = await page.evaluate(([e, n, u]) => window.edoCity.screenOf(e, n, u), [east, north, garden.ground + 0.05]);
    // The first click may land while a tile is still being swapped in: up to three.
    for (let i = 0; i < 3; i++) {
      await page.mouse.click(at.x, at.y);
      out.clicked = await page.evaluate(() => window.edoCity.info);
      if (await page.waitForSelector('#design', { timeout: 10000 }).catch(() => null)) break;
    }
    if (!out.clicked || out.clicked.lot !== garden.lot_id) fail(`the click at the garden named ${JSON.stringify(out.clicked)}`);
    await page.click('#design');
    await page.waitForFunction(() => window.edoCity.garden.generation === 0);
    const g = () => page.evaluate(() => {
      const d = window.edoCity.garden;
      return { generation: d.generation, candidates: d.candidates, session: d.session, picks: d.picks };
    });
    const first = await g();
    out.shown = first.candidates.length;
    if (out.shown < 6 || out.shown > 9) fail(`generation 0 shows ${out.shown} candidates, not 6-9`);
    const cards = await page.$$eval('#dcards canvas', (cs) => cs.length);
    if (cards !== out.shown) fail(`${cards} candidate pictures for ${out.shown} candidates`);
    out.generations = [first];
    const picks = [[0, 2], [1, 3], [0, 1]];
    for (const p of picks) {
      const before = await g();
      // Picks by clicking the candidates' pictures, as a visitor does.
      for (const k of p) await page.click(`#dcards .dcard[data-k="${k}"] canvas`);
      const picked = await page.evaluate(() => window.edoCity.garden.picks);
      if (JSON.stringify(picked) !== JSON.stringify(p)) fail(`clicked ${p}, picks are ${picked}`);
      await page.click('#dnext');
      await page.waitForFunction((n) => window.edoCity.garden.generation === n, before.generation + 1);
      const after = await g();
      if (JSON.stringify(after.candidates) === JSON.stringify(before.candidates)) fail(`picks ${p} did not change generation ${after.generation}`);
      // The picks are kept: each picked layout is in the next generation.
      for (const k of p) {
        const st = JSON.stringify(before.candidates[k].stones);
        if (!after.candidates.some((c) => JSON.stringify(c.stones) === st) && before.candidates[k].fitness >= after.candidates[after.candidates.length - 1].fitness) {
          fail(`picked candidate ${k} of generation ${before.generation} is missing from the next one`);
        }
      }
      out.generations.push({ generation: after.generation, picks: p, fitness: after.candidates.map((c) => c.fitness) });
    }
    // Undo goes back one generation, and the same picks bring the same one again.
    const third = await g();
    await page.click('#dundo');
    await page.waitForFunction(() => window.edoCity.garden.generation === 2);
    await page.evaluate(() => window.edoCity.garden.pick([0, 1]));
    await page.evaluate(() => window.edoCity.garden.next());
    const again = await g();
    if (JSON.stringify(again.candidates) !== JSON.stringify(third.candidates)) fail('undo and the same picks gave another generation');
    // A second session with the same picks: the same answers.
    out.replayed = await page.evaluate(async ([l, ps]) => {
      // A page of its own: its own token.
      const { token } = await (await fetch('/api/token')).json();
      const headers = { 'content-type': 'application/json', 'x-edo-city-token': token };
      const post = async (route, body) => (await fetch(`/api/gardens/${route}`, { method: 'POST', headers, body: JSON.stringify(body) })).json();
      let s = await post('open', { lot: l });
      for (const p of ps) s = await post('next', { session: s.session, generation: s.generation, picks: p });
      return s.candidates;
    }, [garden.lot, picks]);
    if (JSON.stringify(out.replayed) !== JSON.stringify(third.candidates)) fail('a second session with the same picks got other candidates');
    delete out.replayed;
    // Stand candidate 1 in the precinct, then keep it.
    await page.click('#dcards .dcard[data-k="1"] button');
    out.in_place = await page.evaluate(() => window.edoCity.garden.shown);
    if (arg4) await page.screenshot({ path: `${arg4}/garden-designer.jpg`, type: 'jpeg', quality: 85 });
    await page.click('#dkeep');
    await page.waitForFunction(() => window.edoCity.garden.kept !== null);
    out.kept = await page.evaluate(() => window.edoCity.garden.kept);
    out.kept_candidate = third.candidates[1];
  } else if (phase === 'check') {
    await page.evaluate(([e, n, u]) => window.edoCity.lookFrom(e, n, u), [
      garden.corner[0] + (garden.size[0] / 2) * Math.cos(garden.angle) - (garden.size[1] / 2) * Math.sin(garden.angle),
      garden.corner[1] + (garden.size[0] / 2) * Math.sin(garden.angle) + (garden.size[1] / 2) * Math.cos(garden.angle),
      garden.ground,
    ]);
    const stones = () => {
      let n = 0;
      window.edoCity.scene.traverse((o) => { if (o.userData.kind === 'stone' && o.visible) n += 1; });
      return n;
    };
    // `ready` can hold for a frame before the new view's leaves are asked for (the tiles'
    // progress is still the old view's 1): wait for the stones themselves, two minutes at
    // most, so a slow machine is not taken for a garden that was not built.
    await page
      .waitForFunction(() => {
        let n = 0;
        window.edoCity.scene.traverse((o) => { if (o.userData.kind === 'stone' && o.visible) n += 1; });
        return window.edoCity.ready && n > 0;
      }, null, { timeout: 120000 })
      .catch(() => null);
    out.stone_nodes = await page.evaluate(stones);
    if (arg4) await page.screenshot({ path: `${arg4}/garden-kept.jpg`, type: 'jpeg', quality: 85 });
  } else if (phase === 'time') {
    const population = Number(arg4);
    const generations = Number(arg5 ?? 5);
    out.timings = await page.evaluate(async ([l, p, n]) => {
      const d = window.edoCity.garden;
      await d.open(l, p);
      d.timings.length = 0;
      for (let i = 0; i < n; i++) {
        d.pick([0, 1]);
        await d.next();
      }
      return d.timings;
    }, [garden.lot, population, generations]);
  }
} catch (e) {
  fail(`${e.stack || e}`);
} finally {
  await browser.close();
}
if (problems.length) {
  console.error(problems.join('\n'));
  console.log(JSON.stringify(out));
  process.exit(1);
}
console.log(JSON.stringify(out));

/** The hostile page: served from another origin, it attacks the server at `target`. */
async function attack(target, lot) {
  const page = `<!doctype html><title>elsewhere</title><script>
    window.attacked = (async () => {
      const target = ${JSON.stringify(target)};
      const got = {};
      const blind = (route, body) => fetch(target + 'api/gardens/' + route,
        { method: 'POST', mode: 'no-cors', headers: { 'content-type': 'text/plain' }, body: JSON.stringify(body) })
        .then((r) => r.type, (e) => 'failed: ' + e.message);
      got.open = await blind('open', { lot: ${JSON.stringify(lot)} });
      got.keeps = [];
      for (let id = 0; id < 40; id++) {
        got.keeps.push(await blind('keep', { session: id, generation: 0, candidate: 0 }));
        got.keeps.push(await blind('keep', { session: String(id), generation: 0, candidate: 0 }));
      }
      got.token = await fetch(target + 'api/token').then((r) => r.text(), (e) => 'failed: ' + e.message);
      got.json = await fetch(target + 'api/gardens/open', { method: 'POST',
        headers: { 'content-type': 'application/json', 'x-edo-city-token': '0'.repeat(32) },
        body: JSON.stringify({ lot: ${JSON.stringify(lot)} }) })
        .then((r) => 'answered ' + r.status, (e) => 'failed: ' + e.message);
      return got;
    })();
  </script>`;
  return fromElsewhere(page);
}
