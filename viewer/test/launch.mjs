// Debian's chromium (headless, SwiftShader) with the viewer's test settings: no network but
// the server's, each console error, page error and HTTP error collected in `errors`.
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
