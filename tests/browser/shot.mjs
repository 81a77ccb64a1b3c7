// A screenshot of an fbd viewer.html for the docs (not a test): opens
// DIR/viewer.html in headless Chromium as viewer.test.mjs does, seeks to
// the frame at FRACTION of the run (default 0.5) and saves OUT.png.
// scripts/docs-figures.sh uses it for docs/hexapod_rough_viewer.png.
//
//   node shot.mjs DIR OUT.png [FRACTION]
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';

const [dir, out, fraction = '0.5'] = process.argv.slice(2);
if (!dir || !out) {
  console.error('usage: node shot.mjs DIR OUT.png [FRACTION]');
  process.exit(2);
}
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: [
    '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    '--enable-unsafe-swiftshader',
  ],
});
try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 860 }, offline: true });
  const page = await context.newPage();
  await page.goto(pathToFileURL(join(dir, 'viewer.html')).href, { timeout: 120000 });
  await page.waitForFunction(() => window.fbdViewer !== undefined, null, { timeout: 30000 });
  await page.evaluate((f) => {
    const v = window.fbdViewer;
    v.seek(Math.floor((v.frameCount - 1) * f));
  }, Number(fraction));
  await page.screenshot({ path: out, fullPage: true });
} finally {
  await browser.close();
}
