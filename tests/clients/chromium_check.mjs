// Browser client test: node chromium_check.mjs RUN_DIR NODE_MODULES
// Serves the viewer (tools/viewer/) for RUN_DIR on a free port of 127.0.0.1, opens it in the
// system's Chromium (/usr/bin/chromium, driven by playwright-core) at the animation's last
// frame seen from above, saves RUN_DIR/viewer.png, and checks the picture: the sheet covers
// part of it, and lies in two pieces with the background between them (a torn run).
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const [runDir, modules] = process.argv.slice(2);
const here = dirname(fileURLToPath(import.meta.url));
const { serve } = await import(join(here, '..', '..', 'tools', 'viewer', 'serve.mjs'));
const { chromium } = createRequire(join(modules, 'x'))('playwright-core');

// Pixels unlike the background, on a grid of w x h cells; the sizes of their 4-connected
// pieces, largest first.
function pieces(mask, w, h) {
  const seen = new Uint8Array(w * h), sizes = [];
  for (let start = 0; start < w * h; ++start) {
    if (!mask[start] || seen[start]) continue;
    let size = 0;
    const stack = [start];
    seen[start] = 1;
    while (stack.length) {
      const i = stack.pop(), x = i % w, y = (i / w) | 0;
      ++size;
      for (const [nx, ny] of [[x + 1, y], [x - 1, y], [x, y + 1], [x, y - 1]]) {
        const j = ny * w + nx;
        if (nx >= 0 && ny >= 0 && nx < w && ny < h && mask[j] && !seen[j]) { seen[j] = 1; stack.push(j); }
      }
    }
    sizes.push(size);
  }
  return sizes.sort((a, b) => b - a);
}

const server = await serve(runDir, { port: 0, modules });
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium',
                                         args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader'] });
try {
  const page = await browser.newPage({ viewport: { width: 480, height: 360 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(`http://127.0.0.1:${server.address().port}/?frame=last&view=top`);
  await page.waitForFunction(() => window.papertearReady === true, null, { timeout: 60000 });
  await page.screenshot({ path: join(runDir, 'viewer.png') });
  const { w, h, mask } = await page.evaluate(() => {
    const c = document.querySelector('canvas'), w = c.width, h = c.height;
    const ctx = Object.assign(document.createElement('canvas'), { width: w, height: h }).getContext('2d');
    ctx.drawImage(c, 0, 0);
    const px = ctx.getImageData(0, 0, w, h).data, mask = [];
    for (let i = 0; i < w * h; ++i)  // background #1d1f24
      mask.push(Math.abs(px[4 * i] - 0x1d) + Math.abs(px[4 * i + 1] - 0x1f) + Math.abs(px[4 * i + 2] - 0x24) > 24 ? 1 : 0);
    return { w, h, mask };
  });
  const sizes = pieces(mask, w, h), sheet = mask.reduce((a, b) => a + b, 0);
  const big = sizes.filter((s) => s > 0.1 * sheet);
  console.log(`chromium_check: sheet covers ${(100 * sheet / (w * h)).toFixed(1)} % of ${w}x${h}, ` +
              `pieces ${sizes.slice(0, 4).join(', ')}; ${errors.length} page errors`);
  if (errors.length) throw new Error(`page errors: ${errors.join('; ')}`);
  if (sheet < 0.05 * w * h) throw new Error('the picture is (nearly) blank');
  if (big.length !== 2) throw new Error(`expected the sheet in two pieces, found ${big.length} large pieces`);
} finally {
  await browser.close();
  server.close();
}
