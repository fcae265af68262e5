// The viewer in Debian's chromium (headless, WebGL on SwiftShader), driven by playwright-core:
// loads the page `edo-city serve` gives, waits for window.edoCity.ready, and checks that
// nothing failed (console errors, page errors, failed or refused requests), that the picture
// is drawn with roof-grey and plaster-white pixels, that clicking a known house shows its
// lot id, and that switching hypothesis keeps the camera and changes the picture.
// Prints one JSON line of measurements (time to ready, frames per second).
//
// Usage: node test/browser.mjs <url> <house.json> [screenshot.png]
//   house.json: {"lot": "12", "east": 10.5, "north": 20.1, "up": 9.3} (map metres from the
//   build's origin; a point on the house's roof)
import { readFile } from 'node:fs/promises';
import { launchChromium } from './launch.mjs';

const [url, houseFile, shot] = process.argv.slice(2);
if (!url || !houseFile) {
  console.error('usage: node test/browser.mjs <url> <house.json> [screenshot.png]');
  process.exit(2);
}
const house = JSON.parse(await readFile(houseFile, 'utf8'));
const problems = [];
const fail = (m) => problems.push(m);

const browser = await launchChromium();
const out = {};
try {
  const page = await browser.newPage({ viewport: { width: 1024, height: 640 } });
  page.on('console', (m) => {
    if (m.type() === 'error') fail(`console error: ${m.text()}`);
  });
  page.on('pageerror', (e) => fail(`page error: ${e.message}`));
  page.on('requestfailed', (r) => fail(`request failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on('response', (r) => {
    if (r.status() >= 400) fail(`HTTP ${r.status()}: ${r.url()}`);
  });

  const ready = () => page.waitForFunction(() => window.edoCity && window.edoCity.ready, null, { timeout: 120000 });
  const t0 = Date.now();
  // A loaded machine (CI, the whole suite at once) can take long to start the page: the test
  // waits for the viewer's own readiness, not for the load event, with a generous timeout.
  page.setDefaultTimeout(120000);
  await page.goto(`${url}?h=0`, { waitUntil: 'domcontentloaded', timeout: 120000 });
  await ready();
  out.ready_ms = Date.now() - t0;
  out.tiles = await page.evaluate(() => window.edoCity.tiles);
  out.hypotheses = await page.evaluate(() => window.edoCity.hypotheses.map((h) => h.name));
  if (out.tiles < 1) fail('no tile loaded');
  if (out.hypotheses.length < 2) fail('the test serves two hypotheses');

  // Frames per second over two seconds of the animation loop.
  out.fps = await page.evaluate(
    () =>
      new Promise((resolve) => {
        let n = 0;
        const start = performance.now();
        const tick = () => {
          n += 1;
          if (performance.now() - start < 2000) requestAnimationFrame(tick);
          else resolve((n * 1000) / (performance.now() - start));
        };
        requestAnimationFrame(tick);
      }),
  );

  const first = await page.evaluate(() => window.edoCity.sample());
  out.first = first;
  // The viewer's own numbers of the first view.
  out.stats = await page.evaluate(() => {
    const s = window.edoCity.stats;
    return { drawCalls: s.drawCalls, triangles: s.triangles, tilesLoaded: s.tilesLoaded, bytesFetched: s.bytesFetched, fps: s.fps };
  });
  if (first.drawn < first.pixels * 0.2) fail(`the picture is nearly blank: ${first.drawn} of ${first.pixels} pixels drawn`);
  if (first.grey < first.pixels * 0.01) fail(`too few roof-grey pixels: ${first.grey}`);
  if (shot) await page.screenshot({ path: shot });

  // The same view, the other hypothesis: the camera stays, the picture changes.
  const cam = () => page.evaluate(() => window.edoCity.camera());
  const before = await cam();
  await page.evaluate(() => window.edoCity.show(1));
  await ready();
  const after = await cam();
  if (JSON.stringify(before) !== JSON.stringify(after)) fail(`the camera moved on switching: ${JSON.stringify(before)} -> ${JSON.stringify(after)}`);
  const second = await page.evaluate(() => window.edoCity.sample());
  out.second = second;
  if (second.hash === first.hash) fail('switching hypothesis did not change the picture');
  await page.evaluate(() => window.edoCity.show(0));
  await ready();

  // Close to a known house: plaster walls show, and a click on its roof names its lot.
  await page.evaluate((h) => window.edoCity.lookAt(h.east, h.north, h.up, 25), house);
  await page.waitForTimeout(300);
  await ready();
  const near = await page.evaluate(() => window.edoCity.sample());
  out.near = near;
  const at = await page.evaluate((h) => window.edoCity.screenOf(h.east, h.north, h.up), house);
  await page.mouse.click(at.x, at.y);
  try {
    await page.waitForFunction((lot) => window.edoCity.info && window.edoCity.info.lot === lot, house.lot, { timeout: 10000 });
    const text = await page.textContent('#info');
    if (!text.includes(`lot: ${house.lot}`)) fail(`the info panel does not show lot ${house.lot}: ${text}`);
    // The test's town has HTML in its districts: shown as text, never made into elements.
    if (!text.includes('district: <b id=inj>x</b>')) fail(`the district is not shown as text: ${text}`);
    if (await page.evaluate(() => document.getElementById('inj') !== null)) fail('a district became HTML');
    out.clicked = await page.evaluate(() => window.edoCity.info);
  } catch {
    fail(`clicking house ${house.lot} at ${JSON.stringify(at)} showed ${JSON.stringify(await page.evaluate(() => window.edoCity.info))}`);
  }

  // Plaster white, seen from the street at an angle.
  await page.evaluate((h) => window.edoCity.lookFrom(h.east, h.north, h.up), house);
  await page.waitForTimeout(300);
  await ready();
  const street = await page.evaluate(() => window.edoCity.sample());
  if (process.env.STREET_SHOT) await page.screenshot({ path: process.env.STREET_SHOT });
  out.street = street;
  if (street.white < street.pixels * 0.01) fail(`too few plaster-white pixels: ${street.white}`);

  // The ground is under the camera's target, and walking (K) stands the eye on it.
  const target = (await cam()).target;
  const ground = await page.evaluate((t) => window.edoCity.groundAt(t[0], t[2]), target);
  if (typeof ground !== 'number') fail(`no ground under the camera's target ${JSON.stringify(target)}`);
  await page.keyboard.press('k');
  await page.waitForTimeout(300);
  const eye = (await cam()).position;
  const under = await page.evaluate((p) => window.edoCity.groundAt(p[0], p[2]), eye);
  if (typeof under !== 'number' || Math.abs(eye[1] - under - 1.6) > 0.05) fail(`walking: eye at ${eye[1]} over ground ${under}`);
  out.walk = { ground: under, eye: eye[1] };
  await page.keyboard.press('k');
  await page.waitForTimeout(300);

  // A link marker: clicking it names its page (the test does not follow it: no network).
  const links = await page.evaluate(async () => {
    const h = window.edoCity.hypotheses[0];
    return h.links ? (await fetch(`${h.base}links.json`)).json() : [];
  });
  out.links = links.length;
  if (links.length === 0) fail('the fixture build has no links.json');
  for (const l of links.slice(0, 1)) {
    await page.evaluate((l) => {
      window.edoCity.openLinks = false;
      window.edoCity.lookFrom(l.x, l.y, l.z + 12);
    }, l);
    await page.waitForTimeout(200);
    const p = await page.evaluate((l) => window.edoCity.screenOf(l.x, l.y, l.z + 12), l);
    await page.mouse.click(p.x, p.y);
    const info = await page.evaluate(() => window.edoCity.info);
    if (!info || info.link !== l.title) fail(`clicking link ${l.title} showed ${JSON.stringify(info)}`);
    // Its title holds an <img> with an onerror script: text in the link, no element, no run.
    await page.waitForTimeout(200);
    const made = await page.evaluate(() => document.getElementById('inj2') !== null || window.pwned === 1);
    if (made) fail(`a link title became HTML: ${l.title}`);
    if (!(await page.textContent('#info')).includes('<img id=inj2')) fail('the link title is not shown as text');
    out.link = info;
  }

  if (await page.evaluate(() => window.edoCity.errors.length)) fail(`tile errors: ${await page.evaluate(() => window.edoCity.errors.join('; '))}`);
} catch (e) {
  fail(`${e.message}`);
} finally {
  await browser.close();
}
console.log(JSON.stringify(out));
if (problems.length) {
  for (const p of problems) console.error(p);
  process.exit(1);
}
