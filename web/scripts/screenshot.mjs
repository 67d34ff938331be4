// Renders examples/index.html in headless chromium (SwiftShader) and writes examples/screenshot.png.
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launch } from '../test/browser.mjs';
import { serve } from '../test/serve.mjs';

const webDir = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const server = await serve(webDir);
const browser = await launch();
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 720 } });
  page.on('console', (m) => console.log(`console ${m.type()}: ${m.text()}`));
  await page.goto(`${server.url}/examples/index.html`);
  await page.waitForFunction(() => window.msmExample !== undefined, null, { timeout: 120000 });
  await page.waitForTimeout(15000); // a few frames on a CPU
  await page.screenshot({ path: join(webDir, 'examples', 'screenshot.png') });
} finally {
  await browser.close();
  await server.close();
}
