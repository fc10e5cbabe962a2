// tools/browser/threejs-grade.mjs: renders three.js's shadow masks of an exported scene (a .glb of
// `shadowlab export`) in headless Chromium with software WebGL (SwiftShader), one per shadow-map
// type (PCFShadowMap, PCFSoftShadowMap, VSMShadowMap), and its coverage image. Run it through
// tools/threejs-grade.sh, which installs what it needs and grades the masks (docs/threejs.md).
// Usage: node threejs-grade.mjs SCENE.glb OUTDIR [--resolution WxH] [--map-size N] [--bias B]
//        [--normal-bias N] [--chromium PATH]
// --bias and --normal-bias set every light's shadow.bias and shadow.normalBias, in three's own units
// (bias: added to the receiver's normalized shadow-map depth; normalBias: world units along the
// normal); both default to three's 0.
// Writes OUTDIR/threejs-<type>.png (the mask: light visibility, 8-bit linear, 255 = lit),
// OUTDIR/threejs-coverage.png (255 where three.js sees a mesh) and prints one JSON line with the
// image size, three's revision, the settings and each light's shadow camera. Exit 0, or 2 when the
// page or the browser fails.
import { createRequire } from 'node:module';
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import zlib from 'node:zlib';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const nodeDir = process.env.SHADOWLAB_NODE_DIR ? path.resolve(process.env.SHADOWLAB_NODE_DIR) : path.resolve(here, '../../build/node');
const require = createRequire(path.join(nodeDir, 'node_modules', 'noop.js'));
const { chromium } = require('playwright-core');

export const kShadowTypes = ['PCFShadowMap', 'PCFSoftShadowMap', 'VSMShadowMap'];
// SwiftShader is the software WebGL of Chromium builds; since Chromium 137 it needs the "unsafe" opt-in.
const kGlFlags = ['--use-gl=angle', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'];

function fail(msg) { console.error(`threejs-grade: error: ${msg}`); process.exit(2); }

// An 8-bit greyscale PNG (no gamma chunk: the codes are the linear values × 255).
function crc32(buf) {
  let c, crc = 0xffffffff;
  for (let n = 0; n < buf.length; ++n) {
    c = (crc ^ buf[n]) & 0xff;
    for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    crc = (crc >>> 8) ^ c;
  }
  return (crc ^ 0xffffffff) >>> 0;
}
function chunk(type, data) {
  const len = Buffer.alloc(4); len.writeUInt32BE(data.length);
  const td = Buffer.concat([Buffer.from(type, 'ascii'), data]);
  const crc = Buffer.alloc(4); crc.writeUInt32BE(crc32(td));
  return Buffer.concat([len, td, crc]);
}
function writeGreyPng(file, width, height, values) {
  const raw = Buffer.alloc((width + 1) * height);
  for (let y = 0; y < height; ++y) {
    raw[y * (width + 1)] = 0;
    for (let x = 0; x < width; ++x) {
      const v = Math.min(1, Math.max(0, values[y * width + x]));
      raw[y * (width + 1) + 1 + x] = Math.round(v * 255);
    }
  }
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(width, 0); ihdr.writeUInt32BE(height, 4);
  ihdr[8] = 8; ihdr[9] = 0; ihdr[10] = 0; ihdr[11] = 0; ihdr[12] = 0;
  fs.writeFileSync(file, Buffer.concat([Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]), chunk('IHDR', ihdr),
    chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0))]));
}

const args = process.argv.slice(2);
let chromiumPath = process.env.SHADOWLAB_CHROMIUM || '/usr/bin/chromium';
let mapSize = 2048;
let resolution = null;
const shadow = { bias: 0, normalBias: 0 };
const number = (flag, text) => {
  const v = Number(text);
  if (text === undefined || text === '' || !Number.isFinite(v)) fail(`${flag}: not a number: ${text}`);
  return v;
};
const pos = [];
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--chromium') chromiumPath = args[++i];
  else if (args[i] === '--map-size') mapSize = Number(args[++i]);
  else if (args[i] === '--bias') shadow.bias = number('--bias', args[++i]);
  else if (args[i] === '--normal-bias') shadow.normalBias = number('--normal-bias', args[++i]);
  else if (args[i] === '--resolution') {
    resolution = (args[++i] || '').split('x').map(Number);
    if (resolution.length !== 2 || !resolution.every((v) => Number.isInteger(v) && v > 0)) fail(`--resolution: not WxH: ${args[i]}`);
  }
  else pos.push(args[i]);
}
if (pos.length !== 2 || !(Number.isInteger(mapSize) && mapSize > 0))
  fail('usage: threejs-grade.mjs SCENE.glb OUTDIR [--resolution WxH] [--map-size N] [--bias B] [--normal-bias N] [--chromium PATH]');
const [glb, outDir] = pos;
if (!fs.existsSync(glb)) fail(`${glb}: no such file`);
fs.mkdirSync(outDir, { recursive: true });

// The page, three's files and the scene over a local HTTP server (modules do not load from file://).
const threeDir = path.join(nodeDir, 'node_modules', 'three');
const kMime = { '.js': 'text/javascript', '.html': 'text/html', '.glb': 'model/gltf-binary' };
const server = http.createServer((req, res) => {
  const url = decodeURIComponent(req.url.split('?')[0]);
  let file = null;
  if (url === '/favicon.ico') { res.writeHead(204); res.end(); return; }
  if (url === '/') file = path.join(here, 'threejs-grade.html');
  else if (url === '/scene.glb') file = glb;
  else if (url.startsWith('/three/')) file = path.join(threeDir, path.normalize(url.slice(7)));
  if (!file || !fs.existsSync(file)) { res.writeHead(404); res.end(); return; }
  res.writeHead(200, { 'Content-Type': kMime[path.extname(file)] || 'application/octet-stream' });
  fs.createReadStream(file).pipe(res);
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const base = `http://127.0.0.1:${server.address().port}`;

let browser;
try {
  browser = await chromium.launch({ executablePath: chromiumPath, headless: true, args: kGlFlags });
} catch (e) {
  server.close();
  fail(`cannot start ${chromiumPath}: ${e.message.split('\n')[0]}`);
}
const page = await browser.newPage();
const errors = [];
page.on('pageerror', (e) => errors.push(e.message));
page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
try {
  await page.goto(base + '/');
  await page.waitForFunction(() => window.pageReady === true, null, { timeout: 30000 });
  const info = await page.evaluate(() => window.sceneInfo('/scene.glb'));
  if (!info.resolution) throw new Error(`${glb}: no extras.shadowlab.resolution on its camera (not a shadowlab export)`);
  const [w, h] = resolution || info.resolution;
  const renderer = await page.evaluate(() => {
    const g = document.createElement('canvas').getContext('webgl2');
    const d = g && g.getExtension('WEBGL_debug_renderer_info');
    return g ? g.getParameter(d ? d.UNMASKED_RENDERER_WEBGL : g.RENDERER) : null;
  });
  if (!renderer) throw new Error(`no WebGL 2 in Chromium with ${kGlFlags.join(' ')}`);
  const pass = async (type, mode) => {
    const b64 = await page.evaluate(([t, m, s, ww, hh, sh]) => window.renderPass('/scene.glb', ww, hh, t, m, s, sh),
                                    [type, mode, mapSize, w, h, shadow]);
    const buf = Buffer.from(b64, 'base64');
    return new Float32Array(buf.buffer, buf.byteOffset, w * h);
  };
  const seconds = {};  // each shadow type's pass, wall-clock (SwiftShader compiles its programs on first use)
  const coverage = await pass(null, 'coverage');
  writeGreyPng(path.join(outDir, 'threejs-coverage.png'), w, h, coverage);
  const unshadowed = await pass(null, 'unshadowed');
  for (const type of kShadowTypes) {
    const t0 = Date.now();
    const shadowed = await pass(type, 'shadowed');
    // visibility = shadowed / unshadowed Lambert (the irradiance-weighted visibility of the lights);
    // where the unshadowed light is 0 no light arrives: 0, as in the reference's visibility. Outside
    // a spot's cone those pixels count; facing away and on the background they do not.
    const mask = shadowed.map((s, i) => (unshadowed[i] > 1e-6 ? s / unshadowed[i] : 0));
    writeGreyPng(path.join(outDir, `threejs-${type}.png`), w, h, mask);
    seconds[type] = (Date.now() - t0) / 1000;
    console.error(`threejs-grade: ${type} done in ${seconds[type].toFixed(1)} s`);
  }
  if (errors.length) throw new Error(`page errors: ${errors.join(' | ')}`);
  const revision = await page.evaluate(() => window.threeRevision);
  const lights = await page.evaluate(() => window.shadowCameras());
  console.log(JSON.stringify({ width: w, height: h, three: revision, webgl: renderer, mapSize, bias: shadow.bias,
                               normalBias: shadow.normalBias, lights, flags: kGlFlags, seconds }));
} catch (e) {
  await browser.close();
  server.close();
  fail(e.message.split('\n')[0]);
}
await browser.close();
server.close();
