// Debian's chromium (headless, SwiftShader) with the viewer's test settings: no network but
// the server's, each console error, page error and HTTP error collected in `errors`.
import http from 'node:http';
import { chromium } from 'playwright-core';

/** Debian's chromium (`$CHROMIUM`, default /usr/bin/chromium), headless, WebGL on SwiftShader,
 * with nothing of its own reaching for the network (this machine's network is closed). */
export function launchChromium() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    headless: true,
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic'],
  });
}

export async function openPage(viewport = { width: 1280, height: 720 }) {
  const browser = await launchChromium();
  const errors = [];
  const page = await browser.newPage({ viewport });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push(`console error: ${m.text()}`);
  });
  page.on('response', (r) => {
    if (r.status() >= 400) errors.push(`HTTP ${r.status()}: ${r.url()}`);
  });
  page.setDefaultTimeout(600000);
  return { browser, page, errors };
}

/** What the page `html` finds when a browser opens it on another origin (a server of its
 * own on 127.0.0.2): its script leaves a Promise in `window.attacked`, which is returned. */
export async function fromElsewhere(html) {
  const browser = await launchChromium();
  try {
    return await inTabElsewhere(browser, html);
  } finally {
    await browser.close();
  }
}

/** [`fromElsewhere`] in a new tab of `browser`, beside the pages it has open. */
export async function inTabElsewhere(browser, html) {
  const evil = http.createServer((req, res) => {
    res.writeHead(200, { 'content-type': 'text/html; charset=utf-8' });
    res.end(html);
  });
  await new Promise((ok) => evil.listen(0, '127.0.0.2', ok));
  const tab = await browser.newPage();
  try {
    await tab.goto(`http://127.0.0.2:${evil.address().port}/`, { waitUntil: 'load' });
    return await tab.evaluate(() => window.attacked);
  } finally {
    await tab.close();
    evil.close();
  }
}
