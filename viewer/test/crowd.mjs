// The street crowds in the viewer: a walker's node moved by the tile's clip. Opens a served
// build, comes down near a walker (map metres east, north from the origin), pauses the
// crowd, sets the clip to two times and reports where the walker's node is at each (scene
// metres: x east, y up, z south), that a click there names the walker, then whether pause
// holds the time and play moves it on.
// tests/crowd_clip.rs compares the two places with crowds/<tile>.csv; then a click on the
// street there charts its stretch's lambda1-3 over the clip.
//
// Usage: node test/crowd.mjs <url> <person id> <east> <north> <t1> <t2>
import { openPage } from './launch.mjs';

const [url, person, east, north, t1, t2] = process.argv.slice(2);
const { browser, page, errors } = await openPage();
const out = {};
try {
  await page.goto(`${url}?h=0`, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(() => window.edoCity && window.edoCity.ready, null, { polling: 250 });
  await page.evaluate(([e, n]) => window.edoCity.lookAt(Number(e), Number(n), 0, 25), [east, north]);
  // Until the walker's leaf tile is in (the parents above it show no walkers).
  const found = (p) => {
    let hit = false;
    window.edoCity.scene.traverse((o) => {
      if (o.userData.person === p) hit = true;
    });
    return hit;
  };
  await page.waitForFunction(found, person, { polling: 250 });
  Object.assign(out, await page.evaluate(() => ({
    duration: window.edoCity.crowd.duration,
    walkers: window.edoCity.crowd.walkers,
    playing: window.edoCity.crowd.playing,
  })));
  const at = (t) =>
    page.evaluate(
      ([p, time]) => {
        const c = window.edoCity.crowd;
        c.play(false);
        c.setTime(Number(time));
        let node = null;
        window.edoCity.scene.traverse((o) => {
          if (o.userData.person === p) node = o;
        });
        node.updateWorldMatrix(true, false);
        const v = node.getWorldPosition(new node.position.constructor());
        return { time: c.time, at: [v.x, v.y, v.z] };
      },
      [person, t],
    );
  out.first = await at(t1);
  out.second = await at(t2);
  // A click on the walker (paused at t2, at its middle): the viewer names the person, found
  // from the skinned crowd's joint under the pointer.
  const [x, y, z] = out.second.at;
  await page.evaluate(([e, n]) => window.edoCity.lookAt(e, n, 0, 25), [x, -z]);
  await page.waitForFunction(() => window.edoCity.ready, null, { polling: 250 });
  const p0 = await page.evaluate(([e, n, u]) => window.edoCity.screenOf(e, n, u), [x, -z, y + 0.7]);
  await page.mouse.click(p0.x, p0.y);
  out.picked = await page.evaluate(() => window.edoCity.picked && window.edoCity.picked.person);
  // Paused: the time holds over frames drawn (three of them, however slow); played: it moves.
  const frames = () =>
    page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(() => requestAnimationFrame(r)))));
  const time = await page.evaluate(() => window.edoCity.crowd.time);
  await frames();
  out.paused_held = (await page.evaluate(() => window.edoCity.crowd.time)) === time;
  await page.evaluate(() => window.edoCity.crowd.play(true));
  await page.waitForFunction((t) => window.edoCity.crowd.time !== t, time, { polling: 100, timeout: 60000 });
  out.played_on = true;
  // A click on the street under the walker's start (people hidden): its stretch's lambda1-3
  // over the clip, charted.
  await page.click('#toggles input[data-kinds="people"]');
  await page.evaluate(([e, n]) => window.edoCity.lookAt(Number(e), Number(n), 0, 25), [east, north]);
  const p = await page.evaluate(([e, n]) => window.edoCity.screenOf(Number(e), Number(n), 0), [east, north]);
  await page.mouse.click(p.x, p.y);
  await page.waitForFunction(() => window.edoCity.chart !== undefined, null, { polling: 250, timeout: 20000 });
  out.chart = await page.evaluate(() => {
    const c = window.edoCity.chart;
    return c && { street: c.street, points: c.series.length, canvas: Boolean(document.getElementById('lambdas')) };
  });
} catch (e) {
  errors.push(`script: ${e.message}`);
}
out.errors = errors;
await browser.close();
console.log(JSON.stringify(out));
