// Opens a `fignet compare` report in headless Chromium (Debian's, driven by playwright-core) from
// disk with the network blocked, and checks what a person would see: the player renders
// non-blank frames, it advances while playing, the plots are drawn, and the console shows no
// error. Exit 0: pass; 1: fail (the reason on stderr); 77: cannot run here (no Chromium).
//
//   node web/check_report.mjs report.html [screenshot.png]
import { existsSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [report, screenshot] = process.argv.slice(2);
const SKIP = 77;
const chromiumPaths = [process.env.CHROMIUM, '/usr/bin/chromium', '/usr/bin/chromium-browser'];
const executablePath = chromiumPaths.find((p) => p && existsSync(p));

function fail(message) {
  console.error(`check_report: FAIL: ${message}`);
  process.exit(1);
}

if (!report || !existsSync(report)) fail(`no report file '${report}'`);
if (!executablePath) {
  console.error('check_report: skipped: no Chromium (apt-get install chromium)');
  process.exit(SKIP);
}
let chromium;
try {
  ({ chromium } = await import('playwright-core'));
} catch {
  console.error('check_report: skipped: no playwright-core (scripts/install-deps.sh installs it)');
  process.exit(SKIP);
}

const browser = await chromium.launch({
  executablePath,
  // Software WebGL: CI machines have no GPU.
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--ignore-gpu-blocklist'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1300, height: 900 } });
  const problems = [];
  page.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  // The report must be self-contained: any request beyond the file itself is a failure.
  await page.route('**/*', (route) => {
    const url = route.request().url();
    if (url.startsWith('file:') || url.startsWith('data:') || url.startsWith('blob:')) {
      return route.continue();
    }
    problems.push(`network request: ${url}`);
    return route.abort();
  });
  await page.goto(pathToFileURL(resolve(report)).href);
  await page.waitForFunction(() => window.fignetReport && window.fignetReport.ready,
                             null, { timeout: 30000 });

  // Non-blank: the canvas holds more than one colour, in every run's viewport.
  const colours = await page.evaluate(() => {
    const canvas = document.getElementById('player');
    const copy = document.createElement('canvas');
    copy.width = canvas.width;
    copy.height = canvas.height;
    const context = copy.getContext('2d');
    context.drawImage(canvas, 0, 0);
    const pixels = context.getImageData(0, 0, copy.width, copy.height).data;
    const distinct = new Set();
    for (let i = 0; i < pixels.length; i += 4 * 97) {
      distinct.add((pixels[i] << 16) | (pixels[i + 1] << 8) | pixels[i + 2]);
    }
    return distinct.size;
  });
  if (colours < 8) fail(`the player canvas looks blank (${colours} distinct colours)`);

  // The player advances on its own while playing.
  const before = await page.evaluate(() => window.fignetReport.framesShown);
  await page.waitForTimeout(1500);
  const after = await page.evaluate(() => window.fignetReport.framesShown);
  if (!(after > before + 3)) fail(`the player did not advance (${before} -> ${after} frames)`);

  // The plots exist and hold lines or points.
  for (const id of ['translation-plot', 'rotation-plot', 'speed-accuracy']) {
    const marks = await page.evaluate(
      (i) => document.querySelectorAll(`#${i} polyline, #${i} circle`).length, id);
    if (marks === 0) fail(`plot '${id}' is empty`);
  }
  if (screenshot) await page.screenshot({ path: screenshot, fullPage: true });
  if (problems.length > 0) fail(problems.join('; '));
  console.log(`check_report: PASS: ${colours} colours, ${after - before} frames in 1.5 s, ` +
              'plots drawn, no console errors');
} finally {
  await browser.close();
}
