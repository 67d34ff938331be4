// Opens the page of `msm report` in headless Chromium (Debian's, driven by playwright-core from
// web/node_modules) and checks what a reader does with it: no console error and no request off the
// local files, every image loads, a table sorts when a header is clicked (and reverses on the second
// click), an inset opens. On a failure, writes DIR/failure.png (a screenshot of the page) and exits 1.
//
//   node report_page.mjs DIR [CHROMIUM]      DIR: the report's directory (index.html)
import { createRequire } from 'node:module';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [dir, chromiumPath = '/usr/bin/chromium'] = process.argv.slice(2);
if (!dir) {
  console.error('usage: node report_page.mjs DIR [CHROMIUM]');
  process.exit(2);
}
const require = createRequire(path.resolve(path.dirname(new URL(import.meta.url).pathname), '../../web/package.json'));
let chromium;
try {
  ({ chromium } = require('playwright-core'));
} catch (e) {
  console.error('report_page: playwright-core is missing: run `npm ci` in web/ (scripts/bootstrap.sh does)');
  process.exit(77);
}

const failures = [];
const check = (ok, what) => {
  if (!ok) failures.push(what);
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
};

const browser = await chromium.launch({ executablePath: chromiumPath, args: ['--no-sandbox'] });
const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
const consoleErrors = [];
const offline = [];
page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
page.on('pageerror', (e) => consoleErrors.push(String(e)));
page.on('requestfailed', (r) => consoleErrors.push(`request failed: ${r.url()}`));
await page.route('**/*', (route) => {
  const url = route.request().url();
  if (url.startsWith('file:')) return route.continue();
  offline.push(url); // a static page asks no network
  return route.abort();
});

try {
  await page.goto(pathToFileURL(path.resolve(dir, 'index.html')).href, { waitUntil: 'load' });
  // Every image, those in the (closed) inset dialogs included.
  const images = await page.$$eval('img', (all) => all.map((i) => ({ src: i.getAttribute('src'), ok: i.complete && i.naturalWidth > 0 })));
  const broken = images.filter((i) => !i.ok).map((i) => i.src);
  check(images.length > 0 && broken.length === 0, `every image loads (${images.length}; broken: ${broken.join(', ') || 'none'})`);
  check(offline.length === 0, `no request off the local files (${offline.join(', ') || 'none'})`);

  // The first table sorted by its MAE column: ascending, then descending.
  const table = page.locator('table.sortable').first();
  const header = table.locator('th', { hasText: /^MAE/ }).first();
  const column = await header.evaluate((th) => Array.prototype.indexOf.call(th.parentNode.children, th));
  const values = () => table.locator('tbody tr').evaluateAll((rows, c) => rows.map((r) => parseFloat(r.cells[c].dataset.value)), column);
  const before = await values();
  await header.click();
  const ascending = await values();
  await header.click();
  const descending = await values();
  const sorted = [...before].sort((a, b) => a - b);
  check(before.length > 1 && JSON.stringify(ascending) === JSON.stringify(sorted), `a click on MAE sorts ascending (${ascending})`);
  check(JSON.stringify(descending) === JSON.stringify([...sorted].reverse()), `a second click sorts descending (${descending})`);
  check(await header.getAttribute('aria-sort') === 'descending', 'the header shows the order');

  // An inset: clicking its outline on the truth opens its dialog with every technique's window.
  const box = page.locator('.inset-box').first();
  const dialogId = await box.getAttribute('data-inset');
  await box.click();
  const dialog = page.locator(`dialog#${dialogId}`);
  check(await dialog.evaluate((d) => d.open), `clicking an inset opens it (${dialogId})`);
  const insetImages = await dialog.locator('img').evaluateAll((all) => all.map((i) => i.naturalWidth > 0));
  check(insetImages.length > 1 && insetImages.every(Boolean), `the inset shows the window in the truth and every technique (${insetImages.length})`);
  await dialog.locator('button.close').click();
  check(!(await dialog.evaluate((d) => d.open)), 'the inset closes');
  check(consoleErrors.length === 0, `no console error (${consoleErrors.join('; ') || 'none'})`);
} catch (e) {
  check(false, `the page could be driven: ${e.message}`);
}
if (failures.length) {
  const shot = path.resolve(dir, 'failure.png');
  await page.screenshot({ path: shot, fullPage: true }).catch(() => {});
  console.error(`report_page: ${failures.length} check(s) failed; screenshot: ${shot}`);
}
await browser.close();
process.exit(failures.length ? 1 : 0);
