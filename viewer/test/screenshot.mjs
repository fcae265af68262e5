// The docs' pictures of the viewer: `node test/screenshot.mjs <url> <out.png> [split]` against
// `edo-city serve` (docs/pictures/viewer.png: the example town; viewer-split.png: two seeds).
import { launchChromium } from './launch.mjs';

const [url, out, split] = process.argv.slice(2);
const browser = await launchChromium();
const page = await browser.newPage({ viewport: { width: 1200, height: 700 } });
await page.goto(url);
const ready = () => page.waitForFunction(() => window.edoCity && window.edoCity.ready, null, { timeout: 120000 });
await ready();
if (split) await page.evaluate(() => window.edoCity.setSplit(true));
await ready();
await page.screenshot({ path: out });
await browser.close();
