// The docs' pictures of the viewer: `node test/screenshot.mjs <url> <out.png> [split]` against
// `edo-city serve` (docs/pictures/viewer.png: the example town; viewer-split.png: two seeds).
import { chromium } from 'playwright-core';

const [url, out, split] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic'],
});
const page = await browser.newPage({ viewport: { width: 1200, height: 700 } });
await page.goto(url);
const ready = () => page.waitForFunction(() => window.edoCity && window.edoCity.ready, null, { timeout: 120000 });
await ready();
if (split) await page.evaluate(() => window.edoCity.setSplit(true));
await ready();
await page.screenshot({ path: out });
await browser.close();
