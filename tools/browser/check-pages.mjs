// tools/browser/check-pages.mjs: opens HTML pages in headless Chromium (the system's, through
// playwright-core) and prints one line per problem, "PAGE: KIND: ELEMENT: detail"; exits 1 when
// there is any, 2 on bad usage. Run it through tools/browser-check.sh, which installs what it needs.
// Usage: node check-pages.mjs [--screenshots DIR] [--chromium PATH] HTML|DIR...
//
// The checks, each a KIND:
//   console      a console.error() or console.assert failure, or a page error (uncaught exception)
//   request      a request of the page that failed (a file that is not there, a refused URL)
//   image        <img> whose image did not decode (naturalWidth 0), or an SVG <image>, CSS url()
//                or <img> whose local file does not exist
//   link         <a href> to a local file that does not exist, or to #id with no such id
//   svg          an <svg> with a zero-size box, without any drawn shape (path, polyline, polygon,
//                line, circle, ellipse, rect) of non-zero size, or with NaN/Infinity in a coordinate
//   overflow     a box whose content sticks out of it: an element with overflow visible (or hidden
//                or clip: "clipped") whose scrollWidth/scrollHeight exceeds clientWidth/Height by
//                more than 1 px AND one of whose own children (element or text) reaches past its
//                padding box by more than 1 px. Scroll containers (overflow auto/scroll) are
//                deliberate and exempt; only the innermost box is reported, since overflow shows
//                in every ancestor's scroll size too. Also the page itself scrolling sideways.
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL, fileURLToPath } from 'node:url';

const nodeDir = process.env.SHADOWLAB_NODE_DIR || path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../build/node');
const require = createRequire(path.join(nodeDir, 'node_modules', 'noop.js'));

const kViewport = { width: 1280, height: 900 };  // a laptop-sized window
const kSlackPx = 1;  // sub-pixel layout rounds boxes by up to a pixel; not an overflow

function usage(msg) {
  console.error(`check-pages: ${msg}\nusage: check-pages.mjs [--screenshots DIR] [--chromium PATH] HTML|DIR...`);
  process.exit(2);
}

const args = process.argv.slice(2);
let shotDir = null;
let chromiumPath = process.env.SHADOWLAB_CHROMIUM || '/usr/bin/chromium';
const inputs = [];
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--screenshots') shotDir = args[++i];
  else if (args[i] === '--chromium') chromiumPath = args[++i];
  else if (args[i].startsWith('--')) usage(`unknown option ${args[i]}`);
  else inputs.push(args[i]);
}
if (!inputs.length) usage('no page or folder given');

const pages = [];
function collect(p) {
  const st = fs.statSync(p, { throwIfNoEntry: false });
  if (!st) usage(`${p}: no such file or folder`);
  if (st.isDirectory()) {
    for (const e of fs.readdirSync(p).sort()) collect(path.join(p, e));
  } else if (/\.html?$/i.test(p) || inputs.includes(p)) {
    pages.push(path.resolve(p));
  }
}
for (const p of inputs) collect(p);
if (!pages.length) usage(`no .html page in ${inputs.join(' ')}`);

let playwright;
try {
  playwright = require('playwright-core');
} catch (e) {
  console.error(`check-pages: cannot load playwright-core from ${nodeDir} (run tools/browser-check.sh): ${e.message}`);
  process.exit(2);
}

// A local file URL's path, or null for other schemes (http links are not followed: CI has no network).
function localPath(url) {
  try {
    const u = new URL(url);
    return u.protocol === 'file:' ? fileURLToPath(u) : null;
  } catch {
    return null;
  }
}

// Screenshot names: the page's path below the folder given (or the pages' common folder), '/'
// turned into '__'.
const single = inputs.length === 1 && fs.statSync(inputs[0]).isDirectory() ? path.resolve(inputs[0]) : null;
const common = single ? single : pages.length === 1 ? path.dirname(pages[0])
  : pages.reduce((a, p) => { while (!(p + path.sep).startsWith(a + path.sep)) a = path.dirname(a); return a; }, path.dirname(pages[0]));
if (shotDir) fs.mkdirSync(shotDir, { recursive: true });

// Runs in the page: every DOM-side check. Returns [{kind, element, detail}].
function inPageChecks(slack) {
  const out = [];
  const describe = (el) => {
    if (!el || el.nodeType !== 1) return '(text)';
    let s = el.tagName.toLowerCase();
    if (el.id) s += '#' + el.id;
    else if (el.classList.length) s += '.' + [...el.classList].join('.');
    const parts = [s];
    for (let p = el.parentElement; p && parts.length < 4 && p !== document.body; p = p.parentElement) {
      parts.unshift(p.tagName.toLowerCase() + (p.id ? '#' + p.id : ''));
    }
    const text = (el.innerText || el.textContent || '').trim().replace(/\s+/g, ' ');
    return parts.join(' > ') + (text ? ` "${text.length > 40 ? text.slice(0, 40) + '…' : text}"` : '');
  };
  const resolve = (u) => { try { return new URL(u, document.baseURI).href; } catch { return null; } };

  // Images and links: URLs handed back for the file checks in node, and decode failures here.
  const files = [];
  for (const img of document.querySelectorAll('img')) {
    const src = img.getAttribute('src');
    if (!src) { out.push({ kind: 'image', element: describe(img), detail: 'no src' }); continue; }
    files.push({ kind: 'image', element: describe(img), url: resolve(src), attr: src,
                 decoded: img.complete && img.naturalWidth > 0 });
  }
  for (const im of document.querySelectorAll('image')) {
    const href = im.getAttribute('href') || im.getAttributeNS('http://www.w3.org/1999/xlink', 'href');
    if (!href) { out.push({ kind: 'image', element: describe(im), detail: 'SVG image without href' }); continue; }
    files.push({ kind: 'image', element: describe(im), url: resolve(href), attr: href });
  }
  const cssUrls = new Set();
  const addCss = (text, where) => {
    for (const m of text.matchAll(/url\(\s*(['"]?)([^'")]+)\1\s*\)/g))
      if (!m[2].startsWith('data:') && !cssUrls.has(m[2] + where)) {
        cssUrls.add(m[2] + where);
        files.push({ kind: 'image', element: where, url: resolve(m[2]), attr: m[2] });
      }
  };
  for (const st of document.querySelectorAll('style')) addCss(st.textContent, 'style sheet');
  for (const el of document.querySelectorAll('[style]')) addCss(el.getAttribute('style'), describe(el));
  for (const a of document.querySelectorAll('a[href]')) {
    const href = a.getAttribute('href');
    if (href.startsWith('#')) {
      const id = decodeURIComponent(href.slice(1));
      if (id && !document.getElementById(id) && !document.getElementsByName(id).length)
        out.push({ kind: 'link', element: describe(a), detail: `${href}: no element with that id` });
      continue;
    }
    files.push({ kind: 'link', element: describe(a), url: resolve(href), attr: href });
  }

  // SVG plots: the outermost <svg> elements only (nested ones are parts of a plot).
  const shapes = 'path, polyline, polygon, line, circle, ellipse, rect';
  for (const svg of document.querySelectorAll('svg')) {
    if (svg.parentElement && svg.parentElement.closest('svg')) continue;
    const r = svg.getBoundingClientRect();
    if (!(r.width > 0 && r.height > 0)) {
      out.push({ kind: 'svg', element: describe(svg), detail: `zero-size box ${r.width}x${r.height}` });
      continue;
    }
    let drawn = 0;
    for (const s of svg.querySelectorAll(shapes)) {
      const b = s.getBBox();
      // A horizontal or vertical line has one zero side; a shape with both zero draws nothing.
      if (b.width > 0 || b.height > 0) ++drawn;
      for (const a of ['d', 'points', 'x', 'y', 'x1', 'y1', 'x2', 'y2', 'cx', 'cy', 'r', 'width', 'height']) {
        const v = s.getAttribute(a);
        if (v && /nan|inf/i.test(v)) {
          out.push({ kind: 'svg', element: describe(s), detail: `${a}="${v.slice(0, 60)}" is not a number` });
          break;
        }
      }
    }
    if (!drawn) out.push({ kind: 'svg', element: describe(svg), detail: 'draws nothing (no shape of non-zero size)' });
    // Text outside the plot's own box is cut off where the SVG ends (overflow hidden by default).
    for (const t of svg.querySelectorAll('text')) {
      const b = t.getBoundingClientRect();
      if (!(b.width > 0 && b.height > 0)) continue;
      const by = Math.max(b.right - r.right, r.left - b.left, b.bottom - r.bottom, r.top - b.top);
      if (by > slack)
        out.push({ kind: 'overflow', element: describe(t), detail: `SVG text sticks out of its plot (${describe(svg).split(' "')[0]}) by ${Math.round(by)} px` });
    }
  }

  // Overflow: see the header of this file for the definition.
  const sticksOut = (rect, box) =>
    rect.width > 0 || rect.height > 0
      ? rect.right > box.right + slack || rect.left < box.left - slack || rect.bottom > box.bottom + slack
      : false;
  for (const el of document.body.querySelectorAll('*')) {
    if (el.closest('svg') || el.tagName === 'SCRIPT' || el.tagName === 'STYLE') continue;
    const cs = getComputedStyle(el);
    if (cs.display === 'inline' || cs.display === 'none' || cs.display === 'contents') continue;
    const clips = /hidden|clip/.test(cs.overflowX + cs.overflowY);
    if (/auto|scroll/.test(cs.overflowX + cs.overflowY)) continue;
    const wide = el.scrollWidth > el.clientWidth + slack;
    const tall = el.scrollHeight > el.clientHeight + slack && el.clientHeight > 0;
    if (!wide && !tall) continue;
    if (el.tagName === 'IMG' || el.clientWidth === 0) continue;
    const r = el.getBoundingClientRect();
    // The padding box, where content may go.
    const box = {
      left: r.left + el.clientLeft, top: r.top + el.clientTop,
      right: r.left + el.clientLeft + el.clientWidth, bottom: r.top + el.clientTop + el.clientHeight,
    };
    for (const child of el.childNodes) {
      let rect = null;
      let what = null;
      if (child.nodeType === 1) {
        if (getComputedStyle(child).position === 'absolute' || getComputedStyle(child).position === 'fixed') continue;
        rect = child.getBoundingClientRect();
        what = describe(child);
      } else if (child.nodeType === 3 && child.textContent.trim()) {
        const range = document.createRange();
        range.selectNodeContents(child);
        rect = range.getBoundingClientRect();
        what = `text "${child.textContent.trim().slice(0, 40)}"`;
      }
      if (!rect || !sticksOut(rect, box)) continue;
      if (clips && !(child.textContent || '').trim()) continue;  // a clipped picture, not text
      const by = Math.round(Math.max(rect.right - box.right, box.left - rect.left, rect.bottom - box.bottom));
      out.push({
        kind: 'overflow', element: describe(el),
        detail: `${what} ${clips ? 'is clipped' : 'sticks out'} by ${by} px (box ${Math.round(box.right - box.left)}x${Math.round(box.bottom - box.top)} px, content ${el.scrollWidth}x${el.scrollHeight})`,
      });
      break;
    }
  }
  const doc = document.documentElement;
  if (doc.scrollWidth > window.innerWidth + slack)
    out.push({ kind: 'overflow', element: 'page', detail: `scrolls sideways: ${doc.scrollWidth} px wide in a ${window.innerWidth} px window` });
  return { problems: out, files };
}

const browser = await playwright.chromium.launch({ executablePath: chromiumPath, args: ['--no-sandbox'] });
let total = 0;
try {
  const context = await browser.newContext({ viewport: kViewport, deviceScaleFactor: 1 });
  for (const file of pages) {
    const rel = path.relative(process.cwd(), file) || file;
    const report = (kind, element, detail) => {
      ++total;
      console.log(`${rel}: ${kind}: ${element}: ${detail}`);
    };
    const page = await context.newPage();
    page.on('console', (m) => {
      // A file that fails to load is reported once, by the request check.
      if (m.type() === 'error' && m.text().startsWith('Failed to load resource')) return;
      if (m.type() === 'error' || m.type() === 'assert') report('console', m.type(), m.text());
    });
    page.on('pageerror', (e) => report('console', 'page error', e.message));
    const failed = [];  // reported after the file checks, unless those named the file already
    page.on('requestfailed', (r) => failed.push(r));
    try {
      await page.goto(pathToFileURL(file).href, { waitUntil: 'load', timeout: 30000 });
      const { problems, files } = await page.evaluate(inPageChecks, kSlackPx);
      for (const p of problems) report(p.kind, p.element, p.detail);
      const missing = new Set();
      for (const f of files) {
        const url = f.url && f.url.split('#')[0].split('?')[0];
        const local = url && localPath(url);
        if (f.url === null) report(f.kind, f.element, `${f.attr}: not a URL`);
        else if (local !== null && !fs.existsSync(local)) {
          missing.add(url);
          report(f.kind, f.element, `${f.attr}: no such file (${path.relative(process.cwd(), local) || local})`);
        } else if (f.decoded === false) report(f.kind, f.element, `${f.attr}: did not load or decode`);
      }
      for (const r of failed)
        if (!missing.has(r.url().split('#')[0].split('?')[0]))
          report('request', r.resourceType(), `${r.url()}: ${r.failure()?.errorText}`);
      if (shotDir) {
        const name = path.relative(common, file).split(path.sep).join('__').replace(/\.html?$/i, '.png');
        await page.screenshot({ path: path.join(shotDir, name), fullPage: true });
      }
    } catch (e) {
      report('load', 'page', e.message.split('\n')[0]);
    }
    await page.close();
  }
} finally {
  await browser.close();
}
console.error(`check-pages: ${pages.length} page(s), ${total} problem(s)${shotDir ? `; screenshots in ${shotDir}` : ''}`);
process.exit(total ? 1 : 0);
