// The build in CesiumJS (`/viewer/cesium.html`, CesiumJS from npm) in Debian's chromium
// (headless, SwiftShader), driven by playwright-core: waits for the tileset's view to load and
// fails on any console or page error, failed request, HTTP error, tile error or request to
// another host (no Cesium ion, no imagery: offline). Prints one JSON line: the tileset's
// centre (longitude, latitude, height), the tiles loaded, the metadata row of the object at
// the middle of the picture, the time to ready.
//
// Usage: node test/cesium.mjs <url> [screenshot.png | -] [screen-space error target]
// (`-`: no screenshot; a small error target loads the leaves, e.g. 1 for the example town)
import { launchChromium } from './launch.mjs';

const [url, shot, sse] = process.argv.slice(2);
if (!url) {
  console.error('usage: node test/cesium.mjs <url> [screenshot.png | -] [screen-space error target]');
  process.exit(2);
}
const problems = [];
const fail = (m) => problems.push(m);
const browser = await launchChromium();
const out = {};
try {
  const page = await browser.newPage({ viewport: { width: 1024, height: 640 } });
  const origin = new URL(url).origin;
  page.on('console', (m) => {
    if (m.type() === 'error') fail(`console error: ${m.text()}`);
  });
  page.on('pageerror', (e) => fail(`page error: ${e.message}`));
  page.on('requestfailed', (r) => fail(`request failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on('request', (r) => {
    const u = new URL(r.url());
    if (u.protocol.startsWith('http') && u.origin !== origin) fail(`a request left the server: ${r.url()}`);
  });
  page.on('response', (r) => {
    if (r.status() >= 400) fail(`HTTP ${r.status()}: ${r.url()}`);
  });
  page.setDefaultTimeout(120000);
  const t0 = Date.now();
  await page.goto(`${url}viewer/cesium.html?h=0${sse ? `&sse=${sse}` : ''}`, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(() => window.edoCesium && (window.edoCesium.ready || window.edoCesium.errors.length), null, {
    timeout: 120000,
    polling: 250,
  });
  out.ready_ms = Date.now() - t0;
  // A few frames more, then what is drawn in the middle of the picture.
  await page.waitForTimeout(500);
  const api = await page.evaluate(() => ({ centre: window.edoCesium.centre, tilesLoaded: window.edoCesium.tilesLoaded, errors: window.edoCesium.errors }));
  Object.assign(out, api);
  for (const e of api.errors) fail(`tile error: ${e}`);
  if (api.tilesLoaded < 1) fail('no tile loaded');
  out.picked = await page.evaluate(() => window.edoCesium.pick(512, 320));
  if (shot && shot !== '-') await page.screenshot({ path: shot });
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
