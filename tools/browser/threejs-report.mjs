// tools/browser/threejs-report.mjs: writes OUTDIR/report.html, the page of a three.js grading
// (tools/threejs-grade.sh, docs/threejs.md): the reference, then per method (three's
// PCFShadowMap, PCFSoftShadowMap, VSMShadowMap and shadowlab's raster of the same .glb) its mask,
// its difference image and its heat map side by side, a table of the metrics and one paragraph
// per method saying what went wrong and why. Self-contained: inline CSS, images by file name.
// Usage: node threejs-report.mjs OUTDIR --scene NAME [--command TEXT] [--shadowlab TEXT]
// Reads OUTDIR/threejs.json (threejs-grade.mjs's line), OUTDIR/silhouette.json, OUTDIR/METHOD.json
// (`shadowlab compare --json`) and OUTDIR/scene.glb (object names). Exit 0, or 2 on bad input.
import fs from 'node:fs';
import path from 'node:path';

export const kMethods = ['PCFShadowMap', 'PCFSoftShadowMap', 'VSMShadowMap', 'raster'];

function fail(msg) { console.error(`threejs-report: error: ${msg}`); process.exit(2); }

const esc = (s) => String(s).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;').replace(/"/g, '&quot;');
const pc = (r) => (r === 0 ? '0%' : r < 0.0001 ? '<0.01%' : `${(100 * r).toFixed(2)}%`);
const num = (v) => (Number.isInteger(v) ? String(v) : Number(v.toPrecision(4)).toString());

// What the page needs from the .glb: object names by object id (1-based: shadowlab loads a .glb as
// one object per glTF material, in the order of first use, scene/loader.cpp; the export gives each
// object its own material and names its node after the object), which objects are semi-transparent
// (alphaMode BLEND) and the largest light radius (extras.shadowlab.radius; docs/export.md).
function sceneFacts(glbFile) {
  const b = fs.readFileSync(glbFile);
  if (b.length < 20 || b.readUInt32LE(0) !== 0x46546c67 || b.readUInt32LE(16) !== 0x4e4f534a)
    fail(`${glbFile}: not a .glb with a JSON chunk`);
  const gltf = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString('utf8'));
  const names = [];
  const blend = [];
  const seen = new Set();
  const visit = (i) => {
    const n = gltf.nodes[i];
    const prims = n.mesh !== undefined ? gltf.meshes[n.mesh].primitives : [];
    for (const p of prims) {
      const m = p.material ?? -1;
      if (seen.has(m)) continue;
      seen.add(m);
      names.push(n.name || gltf.meshes[n.mesh].name || `object ${names.length + 1}`);
      if (m >= 0 && gltf.materials[m].alphaMode === 'BLEND') blend.push(names[names.length - 1]);
    }
    for (const c of n.children || []) visit(c);
  };
  for (const i of gltf.scenes[gltf.scene ?? 0].nodes) visit(i);
  const lights = gltf.extensions?.KHR_lights_punctual?.lights || [];
  const lightRadius = Math.max(0, ...lights.map((l) => l.extras?.shadowlab?.radius || 0));
  return { names, blend, lightRadius };
}

// The object holding most of a count (per_object of compare's JSON): its name and share.
function topObject(m, key, names) {
  const total = m.per_object.reduce((s, o) => s + o[key], 0);
  if (total === 0) return null;
  const top = m.per_object.reduce((a, o) => (o[key] > a[key] ? o : a));
  return { name: names[top.object_id - 1] || `object ${top.object_id}`, share: top[key] / total };
}
function mostOn(m, key, names) {
  const t = topObject(m, key, names);
  if (!t) return '';
  return t.share === 1 ? `all on “${t.name}”` : `${Math.round(100 * t.share)}% of it on “${t.name}”`;
}

// What a bias of three's means in world units, per light (three's shadow shaders: a directional
// map stores orthographic depth, (d − near)/(far − near); a point light's, the same of the
// distance; a spot's, perspective depth far·(d − near)/(d·(far − near)), whose slope at distance d
// is far·near/((far − near)·d²)).
function biasInWorld(l, bias) {
  const span = l.far - l.near;
  if (l.type === 'SpotLight') {
    const d = l.distance;
    return { world: Math.abs(bias) * (span * d * d) / (l.far * l.near), where: `at the scene's centre, ${num(d)} from the light` };
  }
  return { world: Math.abs(bias) * span, where: 'everywhere' };
}

function describe(method, m, three, facts) {
  const { names } = facts;
  const t = [];
  const counted = m.counted || 1;
  const falseAway = m.false_shadow - m.false_shadow_near_edge;
  const missedAway = m.missed_shadow - m.missed_shadow_near_edge;
  const biased = three.bias !== 0 || three.normalBias !== 0;
  const isThree = method !== 'raster';
  // three has no VSM for point lights: getPointShadow takes the same PCF taps for every type.
  const pointOnly = three.lights.length > 0 && three.lights.every((l) => l.type === 'PointLight');
  const vsm = method === 'VSMShadowMap' && !pointOnly;
  const dirLight = three.lights.find((l) => l.width);
  const texel = dirLight ? ` (${num(dirLight.width / three.mapSize)} wide)` : '';  // a directional map's texel
  t.push(m.mismatch_rate < 0.005
    ? `Close to the reference: ${pc(m.mismatch_rate)} of the counted pixels differ.`
    : `${pc(m.mismatch_rate)} of the counted pixels differ: false shadow ${pc(m.false_shadow_rate)}, missed shadow ${pc(m.missed_shadow_rate)}.`);
  if (method === 'VSMShadowMap' && pointOnly)
    t.push('three has no VSM for point lights: its point-light shadow takes the same PCF taps for every shadow-map type.');
  const topFalse = topObject(m, 'false_shadow', names);
  if (falseAway / counted >= 0.002) {
    const where = mostOn(m, 'false_shadow', names);
    if (isThree && topFalse && facts.blend.includes(topFalse.name) && topFalse.share > 0.5) {
      t.push(`False shadow away from the shadow edges (${pc(falseAway / counted)}, ${where}), a semi-transparent object: three's shadow map holds it as opaque, so it shadows itself fully where the reference lets part of the light through, and its mask is blended with what lies behind it. It cannot be graded there.`);
    } else if (vsm) {
      t.push(`False shadow away from any shadow edge (${pc(falseAway / counted)}, ${where}): dark pixels along the lines where the surface's depth in the map steps. VSM stores the blurred depth and its deviation in about 16 bits each (two 8-bit channels, pack2HalfToRGBA): where a surface's depth barely varies across the blur the stored deviation rounds to 0 and the stored mean can fall just below the surface's own depth, so Chebyshev's bound says fully shadowed.` +
             (biased ? '' : ' A negative bias of more than one step (1/65025) removes it.'));
    } else if (isThree) {
      t.push(!biased
        ? `Self-shadow acne over ${pc(falseAway / counted)} of the counted pixels, ${where}: at bias 0 and normalBias 0 a lit surface is tested against its own depth in the map, rounded to the map's texels, and about half of those tests fail (moiré bands).`
        : `Acne remains over ${pc(falseAway / counted)} of the counted pixels (${where}): bias ${three.bias} and normalBias ${three.normalBias} are less than the depth one texel${texel} spans there, which grows as the light grazes the surface (tan θ per texel).`);
      if (method === 'PCFSoftShadowMap' && !biased) t.push('PCFSoftShadowMap interpolates the same depth tests bilinearly: it blurs the acne, it does not remove it.');
    } else {
      t.push(`False shadow away from the shadow edges (${pc(falseAway / counted)}, ${where}): acne that shadowlab's own bias does not cover.`);
    }
  }
  if (missedAway / counted >= 0.002) {
    const where = mostOn(m, 'missed_shadow', names);
    if (vsm)
      t.push(`Missed shadow away from the edges (${pc(missedAway / counted)}, ${where}): light bleeding. The blurred moments of a caster that is narrow against the blur, or that overlaps another at a different depth, give a Chebyshev bound that lets light through${biased ? '; the bias moves the test toward the light too' : ''}.`);
    else if (isThree && biased)
      t.push(`Missed shadow away from the edges (${pc(missedAway / counted)}, ${where}): peter-panning, the cost of the bias: receivers just behind a blocker (contacts, thin casters) are pushed past it and come out lit.`);
    else
      t.push(`Missed shadow away from the edges (${pc(missedAway / counted)}, ${where}): a caster the map does not hold (thinner than its texels, or cut out) or a leak at a contact.`);
  }
  // Near the edges, unless acne or a leak everywhere explains them too.
  const nearEdge = m.false_shadow_near_edge + m.missed_shadow_near_edge;
  if (nearEdge / counted >= 0.001 && nearEdge >= 0.2 * (m.false_shadow + m.missed_shadow))
    t.push(`${nearEdge} wrong pixels (${pc(nearEdge / counted)}) lie within ${m.edge_radius} px of the reference's shadow edges: ` +
           (vsm ? 'the blur of the moments moves the edge, and three cuts Chebyshev\'s bound below 0.3 (its light-bleeding reduction), which darkens the lit side of a soft edge.'
                : isThree ? `the map's texels${texel} and the filter's blur of the edge.` : 'the map\'s texels and the filter\'s blur of the edge.'));
  if (m.penumbra_pixels / counted >= 0.005) {
    const why = facts.lightRadius > 0 && facts.blend.length ? 'the light has a radius and some objects are semi-transparent'
      : facts.lightRadius > 0 ? `the light has radius ${num(facts.lightRadius)}` : facts.blend.length ? 'semi-transparent casters let part of the light through'
      : 'partly lit';
    const three_ = facts.lightRadius > 0 && facts.blend.length ? 'three draws both hard (KHR_lights_punctual has no light size, and shadow maps ignore opacity)'
      : facts.lightRadius > 0 ? 'three draws it hard (KHR_lights_punctual has no light size: three\'s point and spot lights are points)'
      : facts.blend.length ? 'three\'s shadow map holds such casters as opaque (it ignores opacity) and shadows fully'
      : 'three draws it hard';
    t.push(`The reference is partly lit over ${pc(m.penumbra_pixels / counted)} of the counted pixels (${why}); ` +
           (isThree ? three_ : 'the raster backend\'s filter draws it') + `: mean |ΔV| there ${m.mean_abs_visibility_error_penumbra.toFixed(3)}.`);
  }
  // With a bias the centre tap may pass while PCF's outer taps, a texel or more away, still fail:
  // bands of visibility 0.5 to 0.75, below τ, that only the heat map shows.
  if (isThree && !vsm && biased && falseAway / counted < 0.002 && m.soft_error_rate >= 0.05)
    t.push(`Partial acne over ${pc(m.soft_error_rate)} of the counted pixels (${m.soft_error_pixels}), off by 0.25 to 0.5 in visibility, in bands the heat map shows: the bias covers the depth step of the taps near the lookup, not of the outer taps, a texel${texel} or more away.`);
  else if (m.soft_error_pixels / counted >= 0.001)
    t.push(`${m.soft_error_pixels} pixels (${pc(m.soft_error_rate)}) are off by 0.25 to 0.5 in visibility: wrong, though not in class (the heat map shows them).`);
  return t.join(' ');
}

function figure(caption, note, png, w, h, hot = null) {
  const up = w <= 440 ? ' class="upscale"' : '';
  const box = hot ? `<div class="hot" style="left:${(100 * hot.x) / w}%;top:${(100 * hot.y) / h}%;width:${(100 * hot.size) / w}%;height:${(100 * hot.size) / h}%"></div>` : '';
  return `<figure><figcaption>${esc(caption)}${note ? ` <span>${esc(note)}</span>` : ''}</figcaption>` +
         `<div class="imgwrap"><a href="${esc(png)}"><img src="${esc(png)}" alt="${esc(caption)}" width="${w}" height="${h}"${up}></a>${box}</div></figure>`;
}

// compare's hotspot (the square window with the most wrong pixels) cut out of the difference
// image and magnified with hard pixel edges; pure CSS, as the run report's zoom.
function zoom(png, w, h, hot) {
  return `<figure><figcaption>zoom <span>${hot.wrong_pixels} wrong in ${hot.size}²</span></figcaption><div class="crop">` +
         `<img src="${esc(png)}" alt="zoom of ${esc(png)}" style="width:${(100 * w) / hot.size}%;left:${(-100 * hot.x) / hot.size}%;` +
         `top:${(-100 * hot.y) / hot.size}%"></div></figure>`;
}

const kCss = `
:root { --ink:#1f2933; --muted:#616e7c; --line:#e4e7eb; --bg:#f5f7fa; --card:#fff; }
* { box-sizing: border-box; }
body { margin: 0; background: var(--bg); color: var(--ink); font: 14px/1.5 system-ui, sans-serif; }
main { max-width: 1360px; margin: 0 auto; padding: 24px 28px 48px; }
h1 { margin: 0; font-size: 24px; font-weight: 650; }
.sub { color: var(--muted); margin-top: 2px; overflow-wrap: anywhere; }
h2 { font-size: 17px; margin: 28px 0 10px; font-weight: 650; }
h3 { font-size: 15px; margin: 0 0 6px; }
.card { background: var(--card); border: 1px solid var(--line); border-radius: 8px; padding: 14px 16px; margin-bottom: 14px; }
.row { display: grid; grid-template-columns: repeat(3, minmax(0, 1fr)); gap: 12px; align-items: end; }
.row4 { display: grid; grid-template-columns: repeat(4, minmax(0, 1fr)); gap: 12px; align-items: end; }
.rowz { display: grid; grid-template-columns: repeat(3, minmax(0, 1fr)) minmax(0, 0.5625fr); gap: 12px; align-items: end; }
.imgwrap { position: relative; }
.hot { position: absolute; border: 2px solid #ffd43b; box-shadow: 0 0 0 1px #000; pointer-events: none; }
.crop { position: relative; width: 100%; aspect-ratio: 1 / 1; overflow: hidden; border-radius: 4px; background: #222; }
.crop img { position: absolute; max-width: none; image-rendering: pixelated; }
figure { margin: 0; }
figure img { width: 100%; height: auto; display: block; border-radius: 4px; background: #222; }
img.upscale { image-rendering: pixelated; }
figcaption { font-weight: 600; margin-bottom: 4px; }
figcaption span { font-weight: 400; color: var(--muted); }
p { margin: 6px 0; }
.small { color: var(--muted); font-size: 12px; }
.scroll { overflow-x: auto; }
table { border-collapse: collapse; width: 100%; background: var(--card); }
th, td { padding: 6px 10px; border-bottom: 1px solid var(--line); text-align: right; font-variant-numeric: tabular-nums; }
th:first-child, td:first-child { text-align: left; }
thead th { background: #f0f4f8; font-weight: 600; }
.legend { display: flex; flex-wrap: wrap; gap: 6px 18px; list-style: none; padding: 0; margin: 0; }
.legend li { display: flex; align-items: center; gap: 6px; }
.sw { flex: none; width: 14px; height: 14px; border-radius: 3px; border: 1px solid #0003; }
.heatbar { height: 12px; border-radius: 3px; border: 1px solid #0003; max-width: 420px; }
.heatticks { display: flex; justify-content: space-between; font-size: 12px; color: var(--muted); max-width: 420px; }
.bad { background: #fff5f5; border-color: #ffc9c9; color: #a51111; }
code { font-family: ui-monospace, Menlo, monospace; font-size: 12px; overflow-wrap: anywhere; }
`;

// The difference image's colors (compare/compare.h DiffColors) and the heat map's stops (HeatScale,
// docs/compare.md), as compare writes them.
const kFalse = '#ff140d', kMissed = '#1a66ff', kNotCounted = '#6b6b6b';
const kHeatStops = ['#000005', '#570f6e', '#bd3854', '#fa8f0a', '#fcffa3'];

const kLabels = {
  PCFShadowMap: 'three PCFShadowMap', PCFSoftShadowMap: 'three PCFSoftShadowMap', VSMShadowMap: 'three VSMShadowMap',
  raster: 'shadowlab raster',
};
const kMaskNotes = {
  PCFShadowMap: 'three.js’s mask: 17 depth tests around the texel, averaged',
  PCFSoftShadowMap: 'three.js’s mask: 9 bilinearly weighted depth tests',
  VSMShadowMap: 'three.js’s mask: blurred depth moments, Chebyshev’s bound',
  raster: 'shadowlab’s Vulkan raster of the same .glb, at its own defaults',
};

function main() {
  const args = process.argv.slice(2);
  const opt = { scene: null, command: null, shadowlab: null };
  const pos = [];
  for (let i = 0; i < args.length; ++i) {
    const k = args[i].replace(/^--/, '');
    if (args[i].startsWith('--') && k in opt && i + 1 < args.length) opt[k] = args[++i];
    else if (args[i].startsWith('--')) fail(`unknown option ${args[i]}`);
    else pos.push(args[i]);
  }
  if (pos.length !== 1 || !opt.scene) fail('usage: threejs-report.mjs OUTDIR --scene NAME [--command TEXT] [--shadowlab TEXT]');
  const dir = pos[0];
  const read = (f) => {
    const p = path.join(dir, f);
    if (!fs.existsSync(p)) fail(`${p}: no such file`);
    try { return JSON.parse(fs.readFileSync(p, 'utf8')); } catch (e) { fail(`${p}: not JSON: ${e.message}`); }
  };
  const three = read('threejs.json');
  const sil = read('silhouette.json');
  const metrics = Object.fromEntries(kMethods.map((m) => [m, read(`${m}.json`)]));
  const facts = sceneFacts(path.join(dir, 'scene.glb'));
  const { width: w, height: h } = three;
  const settings = three.bias === 0 && three.normalBias === 0 ? 'bias 0, normalBias 0 (three’s defaults)'
    : `bias ${three.bias}, normalBias ${three.normalBias}`;

  const o = [];
  o.push(`<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>three.js shadows: ${esc(opt.scene)}</title>` +
         `<meta name="viewport" content="width=device-width, initial-scale=1"><style>${kCss}</style></head><body><main>`);
  o.push(`<header><h1>three.js shadows graded: ${esc(opt.scene)}</h1><div class="sub">three r${esc(three.three)} · ${esc(settings)} · ` +
         `${three.mapSize}² shadow map · ${w}x${h} · ${esc(three.webgl)}${opt.shadowlab ? ` · ${esc(opt.shadowlab)}` : ''}</div></header>`);

  // What was graded.
  o.push('<h2>Settings</h2><div class="card">');
  o.push(`<p>Every light casts with <b>${esc(settings)}</b>, in three’s own units: <code>shadow.bias</code> is added to the receiver’s depth in the map ` +
         '(normalized, 0 at the shadow camera’s near plane, 1 at its far plane; negative moves the test toward the light), <code>shadow.normalBias</code> ' +
         'moves the point looked up along its normal, in world units. Every mesh casts and receives, double-sided as the export marks it.</p>');
  o.push('<div class="scroll"><table><thead><tr><th>light</th><th>shadow camera near</th><th>far</th><th>bias in world units</th><th>normalBias</th></tr></thead><tbody>');
  for (const l of three.lights) {
    const b = biasInWorld(l, three.bias);
    o.push(`<tr><td>${esc(l.type)}${l.width ? ` (box ${num(l.width)} wide)` : ''}</td><td>${num(l.near)}</td><td>${num(l.far)}</td>` +
           `<td>${three.bias === 0 ? '0' : `${num(b.world)} (${esc(b.where)})`}</td><td>${num(three.normalBias)}</td></tr>`);
  }
  o.push('</tbody></table></div>');
  if (opt.command) o.push(`<p class="small">Command: <code>${esc(opt.command)}</code></p>`);
  o.push('</div>');

  // The reference and the camera check.
  const silOk = sil.differ <= 0.005 * sil.total;
  o.push('<h2>Reference</h2><div class="row">');
  o.push(figure('reference', 'shadowlab’s ray-traced reference of the .glb', 'reference.png', w, h));
  o.push(figure('reference visibility', 'the mask each method is graded against (white = lit)', 'reference-visibility.png', w, h));
  o.push(figure('silhouettes', `${sil.differ} of ${sil.total} pixels differ`, 'silhouette-diff.png', w, h));
  o.push('</div>');
  o.push(`<div class="card${silOk ? '' : ' bad'}" style="margin-top:12px"><p>${silOk
    ? `The cameras agree: three’s coverage differs from the reference’s in ${sil.differ} of ${sil.total} pixels (${pc(sil.differ / sil.total)}; at most 0.5% allowed).`
    : `The cameras disagree: three’s coverage differs from the reference’s in ${sil.differ} of ${sil.total} pixels (${pc(sil.differ / sil.total)}, over 0.5%); the grades below are not meaningful.`}</p></div>`);

  // Metrics.
  o.push('<h2>Metrics</h2><div class="scroll"><table><thead><tr><th>method</th><th>mismatch</th><th>false shadow</th><th>missed shadow</th>' +
         '<th>mean |ΔV|</th><th>shadow IoU</th><th>counted pixels</th></tr></thead><tbody>');
  for (const k of kMethods) {
    const m = metrics[k];
    o.push(`<tr><td><a href="#${k}">${esc(kLabels[k])}</a></td><td>${pc(m.mismatch_rate)}</td><td>${pc(m.false_shadow_rate)}</td>` +
           `<td>${pc(m.missed_shadow_rate)}</td><td>${m.mean_abs_visibility_error.toFixed(4)}</td><td>${m.shadow_iou.toFixed(3)}</td><td>${m.counted}</td></tr>`);
  }
  o.push('</tbody></table></div>');
  o.push('<p class="small">Over the counted pixels (an object facing the light in the reference). Mismatch = false + missed shadow: |V<sub>method</sub> − ' +
         'V<sub>reference</sub>| &gt; 0.5. A mask carries no blocker ids, so acne is not told apart from other false shadow (docs/external-masks.md).</p>');

  // Per method, side by side: mask, difference, heat.
  o.push('<h2>Methods</h2><div class="card"><ul class="legend">' +
         `<li><span class="sw" style="background:${kFalse}"></span>false shadow: dark where the reference is lit (acne)</li>` +
         `<li><span class="sw" style="background:${kMissed}"></span>missed shadow: lit where the reference is dark (leaks, peter-panning)</li>` +
         `<li><span class="sw" style="background:${kNotCounted}"></span>not counted</li>` +
         '<li>gray: agree (the reference, dimmed); yellow square: the window with the most wrong pixels, zoomed at the right</li></ul>' +
         `<div style="margin-top:8px"><div class="heatbar" style="background:linear-gradient(90deg,${kHeatStops.map((c, i) => `${c} ${25 * i}%`).join(',')})"></div>` +
         '<div class="heatticks"><span>|ΔV| 0</span><span>0.25</span><span>0.5</span><span>0.75</span><span>1</span></div></div></div>');
  o.push('<div class="row4" style="margin-bottom:14px">');
  for (const k of kMethods)
    o.push(figure(kLabels[k], `mismatch ${pc(metrics[k].mismatch_rate)}`, `diff-${k}.png`, w, h));
  o.push('</div>');
  for (const k of kMethods) {
    const m = metrics[k];
    const mask = k === 'raster' ? 'raster-visibility.png' : `threejs-${k}.png`;
    const hot = m.hotspot && m.hotspot.wrong_pixels > 0 ? m.hotspot : null;
    o.push(`<section class="card" id="${k}"><h3>${esc(kLabels[k])}</h3><p>${esc(describe(k, m, three, facts))}</p><div class="${hot ? 'rowz' : 'row'}">`);
    const pointOnly = three.lights.length > 0 && three.lights.every((l) => l.type === 'PointLight');
    const note = k === 'VSMShadowMap' && pointOnly ? 'three.js’s mask: a point light takes PCF’s taps for every type' : kMaskNotes[k];
    o.push(figure('mask', note, mask, w, h));
    o.push(figure('difference', `false ${m.false_shadow}, missed ${m.missed_shadow}`, `diff-${k}.png`, w, h, hot));
    o.push(figure('heat', `mean |ΔV| ${m.mean_abs_visibility_error.toFixed(4)}`, `heat-${k}.png`, w, h));
    if (hot) o.push(zoom(`diff-${k}.png`, w, h, hot));
    o.push('</div></section>');
  }
  o.push('<p class="small">Written by tools/threejs-grade.sh (docs/threejs.md).</p></main></body></html>\n');
  const tmp = path.join(dir, '.report.html.tmp');
  fs.writeFileSync(tmp, o.join('\n'));
  fs.renameSync(tmp, path.join(dir, 'report.html'));
}

main();
