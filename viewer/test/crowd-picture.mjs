// docs/pictures/crowd-street.png: the street crowd of a served boids build seen in walk mode
// from 20 m south of a point of a street running north, the crowd paused at a time, a click
// on the street ahead charting its stretch's lambda1-3. Usage: node test/crowd-picture.mjs <url> <out.png> <east> <north> [time]
import { openPage } from './launch.mjs';

const [url, out, east, north, time] = process.argv.slice(2);
const { browser, page, errors } = await openPage({ width: 1200, height: 700 });
await page.goto(`${url}?h=0`);
const ready = () => page.waitForFunction(() => window.edoCity && window.edoCity.ready, null, { polling: 250 });
await ready();
// Down to the street: walk mode stands 20 m south of the point, at eye height, looking north.
await page.evaluate(([e, n]) => window.edoCity.lookAt(Number(e), Number(n), 0, 40), [east, north]);
await page.keyboard.press('k');
await page.waitForTimeout(500);
await ready();
await page.waitForFunction(() => window.edoCity.crowd.walkers > 0, null, { polling: 250 });
await page.evaluate((t) => {
  window.edoCity.crowd.play(false);
  window.edoCity.crowd.setTime(Number(t || 20));
}, time);
const p = await page.evaluate(([e, n]) => window.edoCity.screenOf(Number(e) + 1.5, Number(n) - 12, 0), [east, north]);
await page.mouse.click(p.x, p.y);
await page.waitForFunction(() => window.edoCity.chart !== undefined, null, { polling: 250, timeout: 20000 }).catch(() => {});
await page.waitForTimeout(300);
await page.screenshot({ path: out });
console.log(JSON.stringify({ errors, chart: await page.evaluate(() => window.edoCity.chart && window.edoCity.chart.street) }));
await browser.close();
