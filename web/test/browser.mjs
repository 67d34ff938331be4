// Debian's chromium, headless, driven by playwright-core, with WebGL 2 on ANGLE's SwiftShader
// (Vulkan on the CPU): the one GPU that every machine has. MSM_CHROMIUM overrides the executable.
import { chromium } from 'playwright-core';
import { existsSync } from 'node:fs';

export const CHROMIUM_ARGS = ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'];

export async function launch() {
  const executablePath = process.env.MSM_CHROMIUM ?? '/usr/bin/chromium';
  if (!existsSync(executablePath)) {
    throw new Error(`${executablePath} not found: scripts/bootstrap.sh installs Debian's chromium (or set MSM_CHROMIUM)`);
  }
  return chromium.launch({ executablePath, headless: true, args: CHROMIUM_ARGS });
}

// A page that fails the test on any console error or uncaught exception it reports.
export async function openPage(browser, url, errors) {
  const page = await browser.newPage();
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push(`console: ${m.text()}`);
  });
  page.on('pageerror', (e) => errors.push(`page: ${e.message}`));
  await page.goto(url);
  return page;
}
