// The workbench of `edo-city serve OUT --edit PARAMS.toml` in Debian's chromium (headless,
// SwiftShader), driven by playwright-core through window.edoCity.edit (issue 61).
//
//   node test/workbench.mjs <url> edit <lot> <type> [screenshot-dir]
//     waits for the server's first build, gives <lot> the machiya type <type> through the
//     lot editor (a click on the house, then its type), looks at it before and after, sets
//     `kura.gap` in the panel, then undoes both; prints one JSON line: each step's answer,
//     the pictures' hashes, the panel's marks.
//   node test/workbench.mjs <url> picture <lot> <type> <screenshot-dir>
//     the picture of docs/workbench.md: the lot's type changed, the lot outlined, the lot
//     editor and the panel's search showing.
//   node test/workbench.mjs <url> save <lot> <type>
//     gives <lot> <type>, lets a page of another site beside it ask for 300 page tokens
//     as `<img src>` does, sets `kura.gap` = 3, saves; prints the answers.
//   node test/workbench.mjs <url> attack
//     a page of another origin POSTs edits and a save (blind no-cors text/plain, and JSON
//     with a made-up token): prints what each attempt got; the caller checks the files.
import { fromElsewhere, inTabElsewhere, openPage } from './launch.mjs';

const [url, phase, lot, type, shots] = process.argv.slice(2);
if (!url || !phase) {
  console.error('usage: node test/workbench.mjs <url> edit|save|attack [lot type [dir]]');
  process.exit(2);
}
if (phase === 'attack') {
  console.log(JSON.stringify(await attack(url)));
  process.exit(0);
}

const { browser, page, errors } = await openPage();
const out = { phase };
try {
  await page.goto(`${url}?h=0`, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(() => window.edoCity && window.edoCity.ready);
  // The panel shows with --edit; the server's first build is then shown.
  await page.waitForFunction(() => window.edoCity.edit.enabled);
  await page.waitForFunction(() => {
    const e = window.edoCity.edit;
    return !e.status.busy && e.status.revision >= 1 && e.shown === e.status.revision && window.edoCity.ready;
  });
  out.first = await page.evaluate(() => window.edoCity.edit.status.revision);
  out.params = await page.evaluate(async () => (await window.edoCity.edit.params()).length);

  if (phase === 'edit') {
    // Where the lot is: the report's houses name no places, so the first edit is made
    // through the API, and its outline says where to look.
    const lotAnswer = await page.evaluate(([l, t]) => window.edoCity.edit.lot(l, 'mtype', t), [lot, type]);
    out.lot = lotAnswer;
    const changed = await page.evaluate(() => window.edoCity.edit.changedLots);
    out.changedLots = changed.map((c) => ({ lot: c.lot, differs: c.differs }));
    const ring = (changed.find((c) => c.lot === lot) || {}).ring || [];
    if (!ring.length) throw new Error(`no outline of lot ${lot}: ${JSON.stringify(out.changedLots)}`);
    const [e, n] = [0, 1].map((i) => ring.reduce((s, p) => s + p[i], 0) / ring.length);
    out.at = [e, n];
    const look = async () => {
      await page.evaluate(([x, y]) => window.edoCity.lookFrom(x, y, 2), [e, n]);
      await page.waitForFunction(() => window.edoCity.ready);
      return page.evaluate(() => window.edoCity.sample());
    };
    const after = await look();
    out.outlines = await page.evaluate(() => window.edoCity.scene.getObjectByName('changed lots').children.length);
    if (shots) await page.screenshot({ path: `${shots}/workbench-lot.png` });
    // The house clicked: the lot editor shows its type, and its type select edits it.
    const at = await page.evaluate(([x, y]) => window.edoCity.screenOf(x, y, 3), [e, n]);
    await page.mouse.click(at.x, at.y);
    out.clicked = await page.evaluate(() => window.edoCity.info);
    out.editor = await page.evaluate(() => {
      const s = document.querySelector('#wlot select[data-field="mtype"]');
      return s ? { title: document.querySelector('.wlottitle').textContent, value: s.value } : null;
    });

    // A parameter from the panel: the search box finds it, the input sets it.
    await page.fill('#wsearch', 'kura.gap');
    await page.fill('.wparam[data-key="kura.gap"] input', '3');
    const before = await page.evaluate(() => window.edoCity.edit.status.revision);
    await page.press('.wparam[data-key="kura.gap"] input', 'Enter');
    await page.waitForFunction((r) => {
      const e = window.edoCity.edit;
      return e.status.revision > r && !e.status.busy && e.shown === e.status.revision && window.edoCity.ready;
    }, before);
    await page.waitForSelector('.wparam.changed[data-key="kura.gap"]');
    out.gap = await page.evaluate(() => ({ ...window.edoCity.edit.status, changedLots: undefined }));
    out.marked = await page.$$eval('.wparam.changed', (rows) => rows.map((r) => r.dataset.key));
    if (shots) await page.screenshot({ path: `${shots}/workbench-panel.png` });

    // Undo both: the picture there is the one before the lot's edit.
    out.undo = [
      await page.evaluate(() => window.edoCity.edit.undo()),
      await page.evaluate(() => window.edoCity.edit.undo()),
    ];
    const undone = await look();
    out.redoAfterUndo = await page.evaluate(() => window.edoCity.edit.status.redo);
    // Outlined against the one build served (itself): nothing differs; back to the revisions.
    out.againstSelf = await page.evaluate(async () => (await window.edoCity.edit.compare(0)).length);
    await page.evaluate(() => window.edoCity.edit.compare(null));
    out.pictures = { after: after.hash, undone: undone.hash, drawn: [after.drawn, undone.drawn] };
  } else if (phase === 'picture') {
    // The picture of docs/workbench.md: a lot's type changed, seen from above with its
    // outline, the house clicked so the lot editor shows it, the panel's search used.
    out.lot = await page.evaluate(([l, t]) => window.edoCity.edit.lot(l, 'mtype', t), [lot, type]);
    const ring = (await page.evaluate(() => window.edoCity.edit.changedLots)).find((c) => c.lot === lot).ring;
    const [e, n] = [0, 1].map((i) => ring.reduce((s, p) => s + p[i], 0) / ring.length);
    await page.evaluate(([x, y]) => window.edoCity.lookAt(x, y, 0, 55), [e, n]);
    await page.waitForFunction(() => window.edoCity.ready);
    // The house stands at the front of its lot: points between the middle and each corner
    // are tried until one is the house.
    for (const [cx, cy] of [[e, n], ...ring.map(([x, y]) => [(x + e) / 2, (y + n) / 2])]) {
      const at = await page.evaluate(([x, y]) => window.edoCity.screenOf(x, y, 6), [cx, cy]);
      await page.mouse.click(at.x, at.y);
      const info = await page.evaluate(() => window.edoCity.info);
      if (info && info.lot === lot && info.kind === 'machiya') break;
    }
    await page.waitForSelector('#wlot select[data-field="mtype"]', { timeout: 5000 }).catch(() => null);
    await page.fill('#wsearch', 'kura');
    await page.screenshot({ path: `${shots}/workbench.png` });
    out.clicked = await page.evaluate(() => window.edoCity.info);
  } else if (phase === 'save') {
    out.lot = await page.evaluate(([l, t]) => window.edoCity.edit.lot(l, 'mtype', t), [lot, type]);
    // Another site open beside it asks for 300 page tokens the way `<img src>` does
    // (issue 74: they pushed this page's token out); this page's next edits must still go.
    out.flood = await inTabElsewhere(browser, `<!doctype html><script>
      window.attacked = Promise.all(Array.from({ length: 300 }, (_, i) => new Promise((ok) => {
        const img = new Image();
        img.onload = () => ok('loaded');
        img.onerror = () => ok('failed');
        img.src = ${JSON.stringify(url)} + 'api/token?' + i;
      }))).then((all) => all.length);
    </script>`);
    out.gap = await page.evaluate(() => window.edoCity.edit.set('kura.gap', 3.0));
    out.saved = await page.evaluate(() => window.edoCity.edit.save());
    out.status = await page.evaluate(() => window.edoCity.edit.status);
  }
  out.errors = errors;
} finally {
  await browser.close();
}
console.log(JSON.stringify(out));

/** What a page of another origin gets when it tries to edit and save. */
async function attack(target) {
  const page = `<!doctype html><title>elsewhere</title><script>
    window.attacked = (async () => {
      const target = ${JSON.stringify(target)};
      const blind = (route, body) => fetch(target + 'api/edit/' + route,
        { method: 'POST', mode: 'no-cors', headers: { 'content-type': 'text/plain' }, body: JSON.stringify(body) })
        .then((r) => r.type, (e) => 'failed: ' + e.message);
      const got = {};
      got.set = await blind('set', { key: 'seed', value: 99 });
      got.lot = await blind('lot', { lot: '1', field: 'use', value: 'buke' });
      got.save = await blind('save', {});
      got.token = await fetch(target + 'api/token').then((r) => r.text(), (e) => 'failed: ' + e.message);
      got.json = await fetch(target + 'api/edit/save', { method: 'POST',
        headers: { 'content-type': 'application/json', 'x-edo-city-token': '0'.repeat(32) },
        body: '{}' }).then((r) => 'answered ' + r.status, (e) => 'failed: ' + e.message);
      return got;
    })();
  </script>`;
  return fromElsewhere(page);
}
