// The first overview of a served build, measured from the viewer's own numbers
// (window.edoCity.stats) in Debian's chromium (headless, SwiftShader), 1280 x 720: time to
// ready, bytes fetched, draw calls and triangles a frame, frames per second over 3 s, the
// build's files fetched and any error; then the same at street level in walk mode at a given
// point (and there again with the street crowd paused, when the build has walkers). Its times
// are for BENCHMARKS.md (issues 40, 41); its counts are what tests/first_view.rs holds to
// the level-of-detail budget.
//
// Usage: [CLICK=object.json] node test/first-view.mjs <url> [east north]
import { readFile } from 'node:fs/promises';
import { launchChromium } from './launch.mjs';

const [url, east, north] = process.argv.slice(2);
const browser = await launchChromium();
const out = { errors: [] };
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 720 } });
  page.on('pageerror', (e) => out.errors.push(`page error: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() === 'error') out.errors.push(`console error: ${m.text()}`);
  });
  page.on('response', (r) => {
    if (r.status() >= 400) out.errors.push(`HTTP ${r.status()}: ${r.url()}`);
  });
  page.setDefaultTimeout(600000);
  const t0 = Date.now();
  await page.goto(`${url}?h=0`, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(() => window.edoCity && window.edoCity.ready, null, { timeout: 600000, polling: 250 });
  out.ready_s = (Date.now() - t0) / 1000;
  const measure = () =>
    page.evaluate(
      () =>
        new Promise((resolve) => {
          setTimeout(() => {
            const s = window.edoCity.stats;
            resolve({ drawCalls: s.drawCalls, triangles: s.triangles, tilesLoaded: s.tilesLoaded, bytesFetched: s.bytesFetched, fps: s.fps });
          }, 3000);
        }),
    );
  out.overview = await measure();
  // The panel's kind toggles on the overview's parents: trees off, then on again (the
  // triangles drawn and the picture, and the tree nodes still shown).
  const toggled = () =>
    page.evaluate(() => {
      window.edoCity.stats.triangles = 0;
      return new Promise((resolve) =>
        requestAnimationFrame(() =>
          requestAnimationFrame(() => {
            let shown = 0;
            window.edoCity.scene.traverse((o) => {
              if (o.userData.kind === 'trees' && o.visible) shown += 1;
            });
            resolve({ triangles: window.edoCity.stats.triangles, hash: window.edoCity.sample().hash, treeNodesShown: shown });
          }),
        ),
      );
    });
  out.toggle = { on: await toggled() };
  await page.click('#toggles input[data-kinds="trees"]');
  out.toggle.off = await toggled();
  await page.click('#toggles input[data-kinds="trees"]');
  out.toggle.again = await toggled();
  // What the first view fetched: each of the builds' files (path under the build) and its bytes.
  out.fetched = await page.evaluate(() =>
    performance
      .getEntriesByType('resource')
      .map((e) => new URL(e.name).pathname)
      .filter((p) => p.startsWith('/h/')),
  );
  if (process.env.CLICK) {
    // Close to a given object ({"east", "north", "up"}: map metres from the origin), a click
    // there: what the info panel names (tests/first_view.rs clicks an instanced tree).
    const t = JSON.parse(await readFile(process.env.CLICK, 'utf8'));
    await page.evaluate((h) => window.edoCity.lookAt(h.east, h.north, h.up, 20), t);
    await page.waitForTimeout(500);
    await page.waitForFunction(() => window.edoCity.ready, null, { timeout: 600000, polling: 250 });
    const at = await page.evaluate((h) => window.edoCity.screenOf(h.east, h.north, h.up), t);
    // Until the leaf replaces its parent (both name the tree; only the leaf draws it as an
    // instance), for at most a minute.
    for (let i = 0; i < 120; i += 1) {
      await page.evaluate(() => {
        window.edoCity.info = null;
      });
      await page.mouse.click(at.x, at.y);
      await page.waitForTimeout(500);
      out.picked = await page.evaluate(() => window.edoCity.picked);
      if (out.picked && out.picked.instance !== null) break;
    }
    out.clicked = await page.evaluate(() => window.edoCity.info);
  }
  out.errors.push(...(await page.evaluate(() => window.edoCity.errors)));
  if (east !== undefined) {
    // Walk mode at the point; the tiles of the new view are given 20 s to stream in.
    await page.evaluate(([e, n]) => window.edoCity.lookAt(Number(e), Number(n), 0, 30), [east, north]);
    await page.keyboard.press('k');
    await page.waitForTimeout(20000);
    out.street = await measure();
    // With walkers, the same view with the crowd paused (issue 41: frames a second playing
    // against paused).
    out.walkers = await page.evaluate(() => window.edoCity.crowd.walkers);
    if (out.walkers > 0) {
      await page.evaluate(() => window.edoCity.crowd.play(false));
      out.street_paused = await measure();
    }
  }
} finally {
  await browser.close();
}
console.log(JSON.stringify(out));
