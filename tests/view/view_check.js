/* view_check.js -- `jetfit view` in a real browser (headless Chromium,
 * WebGL through SwiftShader).  node view_check.js JETFIT MODE, MODE one of
 *   colours  generated sphere: one colour, the one the bar shows for k1;
 *            paraboloid: every sampled point has the bar's colour of its
 *            k1 (values read from the PLY here, independently), clipping,
 *            glyph toggles, the status filter, picking, no request
 *   hostile  markup in file, column and title names stays text; NaN rows
 *   large    10^6 points: bytes per point, time to first frame (printed,
 *            not asserted), --max-points's subsample spread over the cloud
 * Exit 0 pass, 1 fail, 77 skip (no Chromium or no three.js). */
'use strict';
const fs = require('fs');
const os = require('os');
const path = require('path');
const { execFileSync } = require('child_process');
const { findChromium, launch } = require('./cdp');

const [jetfit, mode] = process.argv.slice(2);
const W = 1000, H = 700;
let failures = 0;
const T0 = Date.now();
function check(ok, what) {
  console.log((ok ? 'ok   ' : 'FAIL ') + what + ` [${((Date.now() - T0) / 1000).toFixed(1)} s]`);
  if (!ok) failures++;
}
function skip(why) { console.log('SKIP: ' + why); process.exit(77); }

const chrome = findChromium();
if (!chrome) skip('no chromium (Debian: apt-get install chromium)');
const ver = execFileSync(jetfit, ['--version']).toString();
if (!/view: three\.js r\d+/.test(ver)) skip('no three.js for jetfit view (Debian: libjs-three): ' + ver.trim().split('\n').pop());
const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'jf_view_'));
function run(args) { return execFileSync(jetfit, args, { stdio: ['ignore', 'pipe', 'pipe'] }).toString(); }

/* binary little-endian or ascii PLY vertex table, read here */
function readPLY(file) {
  const b = fs.readFileSync(file), end = b.indexOf('end_header\n') + 11;
  const hdr = b.toString('latin1', 0, end).split('\n');
  const props = [];
  let n = 0, ascii = false;
  for (const l of hdr) {
    const t = l.trim().split(/\s+/);
    if (t[0] === 'format') ascii = t[1] === 'ascii';
    if (t[0] === 'element') n = +t[2];
    if (t[0] === 'property') props.push({ type: t[1], name: t[2] });
  }
  const size = { double: 8, float64: 8, float: 4, float32: 4, int: 4, int32: 4, uint: 4, uchar: 1, uint8: 1, ushort: 2, short: 2 };
  const cols = {};
  props.forEach((p) => { cols[p.name] = new Float64Array(n); });
  if (ascii) {
    const lines = b.toString('latin1', end).split('\n');
    for (let i = 0; i < n; i++) { const t = lines[i].trim().split(/\s+/); props.forEach((p, k) => { cols[p.name][i] = +t[k]; }); }
    return { n, cols };
  }
  let o = end;
  for (let i = 0; i < n; i++)
    for (const p of props) {
      const t = p.type, v = t === 'double' || t === 'float64' ? b.readDoubleLE(o) : t === 'float' || t === 'float32' ? b.readFloatLE(o)
        : t === 'int' || t === 'int32' ? b.readInt32LE(o) : t === 'uint' ? b.readUInt32LE(o) : t === 'uchar' || t === 'uint8' ? b.readUInt8(o)
        : t === 'ushort' ? b.readUInt16LE(o) : b.readInt16LE(o);
      cols[p.name][i] = v;
      o += size[t];
    }
  return { n, cols };
}
function dist(a, b) { return Math.max(Math.abs(a[0] - b[0]), Math.abs(a[1] - b[1]), Math.abs(a[2] - b[2])); }
function quantile(s, p) { const x = p / 100 * (s.length - 1), j = Math.floor(x), f = x - j; return j + 1 < s.length ? s[j] * (1 - f) + s[j + 1] * f : s[j]; }
function sample(n, k) { const o = []; for (let i = 0; i < k; i++) o.push(Math.floor((i + 0.5) * n / k)); return o; }

async function colours(b) {
  const fileURL = (f) => 'file://' + f;
  /* 1. a sphere coloured by its exact k1 (-1 everywhere): one colour */
  run(['generate', 'sphere', '-o', path.join(dir, 's.ply'), '--n', '3000', '--truth', path.join(dir, 'st.ply')]);
  run(['view', path.join(dir, 'st.ply'), '-o', path.join(dir, 's.html'), '--color', 'k1', '--quiet']);
  await b.open(fileURL(path.join(dir, 's.html')), 20000);
  await b.eval('__jetfit.setPointSize(3)');
  let shot = await b.screenshot();
  const promised = await b.eval('__jetfit.colorOf(-1)'), bp = await b.eval('__jetfit.barPixel(-1)');
  const bar = shot.at(bp[0], bp[1]);
  check(dist(bar, promised) <= 1, `sphere: the bar shows k1 = -1 as the colour the page promises (${bar} vs ${promised})`);
  const cv = await b.eval('(function(){var r=document.querySelector("#view canvas").getBoundingClientRect();return [r.left,r.top,r.width,r.height];})()');
  let drawn = 0, same = 0;
  for (let y = Math.ceil(cv[1]); y < cv[1] + cv[3]; y += 2)
    for (let x = Math.ceil(cv[0]); x < cv[0] + cv[2]; x += 2) {
      const c = shot.at(x + 0.5, y + 0.5);
      if (c[0] === 255 && c[1] === 255 && c[2] === 255) continue;
      drawn++;
      if (dist(c, bar) <= 2) same++;
    }
  check(drawn > 2000 && same / drawn > 0.999, `sphere: ${same} of ${drawn} drawn pixels have the bar's colour for k1 = -1`);

  /* 2. a paraboloid z = 2x^2 + y^2 by its exact k1, from above: the gradient */
  run(['generate', 'paraboloid', '-o', path.join(dir, 'p.ply'), '--n', '3000', '--truth', path.join(dir, 'pt.ply')]);
  run(['view', path.join(dir, 'pt.ply'), '-o', path.join(dir, 'p.html'), '--color', 'k1', '--quiet']);
  const truth = readPLY(path.join(dir, 'pt.ply'));
  await b.open(fileURL(path.join(dir, 'p.html')), 20000);
  await b.eval('__jetfit.view("top"); __jetfit.setPointSize(3)');
  shot = await b.screenshot();
  const k1s = Array.from(truth.cols.k1).sort((a, c) => a - c);
  const range = await b.eval('__jetfit.range()');
  const lo = quantile(k1s, 2), hi = quantile(k1s, 98);
  check(Math.abs(range[0] - lo) < 2e-3 * Math.abs(hi) && Math.abs(range[1] - hi) < 2e-3 * Math.abs(hi) && !range[2],
    `paraboloid: the bar spans the 2nd..98th percentiles of k1 (${range[0].toFixed(4)}..${range[1].toFixed(4)} vs ${lo.toFixed(4)}..${hi.toFixed(4)})`);
  let match = 0, tried = 0;
  const entries = new Set();
  const idx = sample(truth.n, 300), vals = idx.map((i) => truth.cols.k1[i]);
  const where = await b.eval(`(function(){var I=${JSON.stringify(idx)},V=${JSON.stringify(vals)};` +
    'return I.map(function(i,k){return [__jetfit.screenOfRow(i), __jetfit.barPixel(V[k])];});})()');
  for (const [s, bpx] of where) {
    if (!s) continue;
    const want = shot.at(bpx[0], bpx[1]), got = shot.at(s[0], s[1]);
    tried++;
    if (dist(want, got) <= 6) match++;
    entries.add(want.join(','));
  }
  check(tried >= 290 && match / tried >= 0.9, `paraboloid: ${match} of ${tried} points have the bar's colour of their own k1`);
  check(entries.size >= 40, `paraboloid: a gradient (${entries.size} distinct bar colours among the sampled points)`);
  await b.eval('__jetfit.setClip(10, 90)');
  const r2 = await b.eval('__jetfit.range()');
  check(Math.abs(r2[0] - quantile(k1s, 10)) < 2e-3 * hi && Math.abs(r2[1] - quantile(k1s, 90)) < 2e-3 * hi,
    'paraboloid: clipping at 10..90% moves the bar to those percentiles');

  /* 3. an estimate's result: glyph toggles, status filter, picking */
  run(['estimate', path.join(dir, 'p.ply'), '-o', path.join(dir, 'e.ply'), '--quiet', '--threads', '1']);
  run(['view', path.join(dir, 'e.ply'), '-o', path.join(dir, 'e.html'), '--quiet']);
  const est = readPLY(path.join(dir, 'e.ply'));
  await b.open(fileURL(path.join(dir, 'e.html')), 20000);
  await b.eval('__jetfit.view("top")');
  const before = await b.screenshot();
  function diff(a, c) { let n = 0; for (let y = 0; y < H; y += 1) for (let x = 300; x < W; x += 1) if (dist(a.at(x + .5, y + .5), c.at(x + .5, y + .5)) > 0) n++; return n; }
  function count(a, rgb) { let n = 0; for (let y = 0; y < H; y++) for (let x = 300; x < W; x++) if (dist(a.at(x + .5, y + .5), rgb) <= 1) n++; return n; }
  for (const [g, rgb] of [['d1', [0xe4, 0x1a, 0x1c]], ['d2', [0x1f, 0x4f, 0xd8]], ['normal', [0x20, 0x20, 0x20]]]) {
    await b.eval(`__jetfit.toggle("${g}", true)`);
    const on = await b.screenshot();
    await b.eval(`__jetfit.toggle("${g}", false)`);
    const off = await b.screenshot();
    check(diff(before, on) > 1000 && count(on, rgb) > 500 && count(before, rgb) < 50,
      `glyphs ${g}: on, ${count(on, rgb)} pixels of their colour (${count(before, rgb)} before)`);
    check(diff(before, off) === 0, `glyphs ${g}: off again, the picture is the first one exactly`);
  }
  let ok0 = 0;
  for (let i = 0; i < est.n; i++) ok0 += est.cols.status[i] === 0;
  await b.eval('__jetfit.setFlags([-1])');
  const nv = await b.eval('__jetfit.nvisible()');
  check(nv === ok0, `status filter "ok": ${nv} points shown, ${ok0} rows with status 0 in the file`);
  const fl = [...new Set(Array.from(est.cols.status))].filter((s) => s > 0);
  if (fl.length) {
    const bit = Math.log2(fl[0] & -fl[0]);
    let nb = 0;
    for (let i = 0; i < est.n; i++) nb += (est.cols.status[i] & (1 << bit)) !== 0;
    await b.eval(`__jetfit.setFlags([${bit}])`);
    check((await b.eval('__jetfit.nvisible()')) === nb, `status filter bit ${bit}: ${nb} points`);
  }
  await b.eval('__jetfit.setFlags([])');
  let picked = 0, pickTried = 0, rowsOK = 0;
  for (const i of sample(est.n, 25)) {
    const s = await b.eval(`__jetfit.screenOfRow(${i})`);
    if (!s) continue;
    pickTried++;
    const o = await b.eval(`__jetfit.pick(${s[0]}, ${s[1]})`);
    if (!o) continue;
    if (o.row === i) picked++;
    else { const t = await b.eval(`__jetfit.screenOfRow(${o.row})`); if (Math.abs(t[0] - s[0]) <= 1 && Math.abs(t[1] - s[1]) <= 1 && t[2] <= s[2]) picked++; /* drawn over it */ }
    /* the row: every column against the file (packing tolerances) */
    const v = o.values, r = o.row, c = est.cols;
    const ks = Math.max(...Array.from(c.k1).map(Math.abs));
    const good = Math.abs(v.k1 - c.k1[r]) <= 1e-3 * Math.abs(c.k1[r]) + ks * 2e-4 && v.degree === c.degree[r] &&
      v.neighbors === c.neighbors[r] && v.status === c.status[r] && Math.abs(v.cond - c.cond[r]) <= 1e-3 * c.cond[r] &&
      Math.abs(v.pos[0] - c.x[r]) < 1e-4 && Math.abs(v.normal[2] - c.nz[r]) < 0.03;
    rowsOK += good;
  }
  check(pickTried >= 20 && picked === pickTried, `picking: ${picked} of ${pickTried} clicks return the row drawn there`);
  check(rowsOK === pickTried, `picking: ${rowsOK} of ${pickTried} rows agree with the file`);

  /* 4. no request leaves the page; the policy forbids them */
  const bad = b.events.filter((e) => e.method === 'Network.requestWillBeSent' && !/^(file:|data:|about:)/.test(e.params.request.url));
  const csp = await b.eval('document.querySelector("meta[http-equiv=Content-Security-Policy]").content');
  const blocked = await b.eval('fetch("http://127.0.0.1:9/x").then(function(){return "sent"}, function(){return "blocked"})');
  check(bad.length === 0 && /default-src 'none'/.test(csp) && blocked === 'blocked',
    `no network: ${bad.length} requests, policy "${csp.slice(0, 40)}...", a fetch is ${blocked}`);
  const leaked = b.events.filter((e) => e.method === 'Network.requestWillBeSent' && /127\.0\.0\.1/.test(e.params.request.url) && e.params.type !== 'Fetch');
  check(leaked.length === 0, 'no network: the blocked fetch sent nothing');
}

async function hostile(b) {
  const name = 'x<script>alert(1)<!--&amp;.csv', title = '</title><script>window.__pwned=1</script>';
  const f = path.join(dir, name);
  fs.writeFileSync(f, 'x,y,z,k1,<img/src=q/onerror=__pwned=2>,</script>\n0,0,0,1,2,3\n1,0,0,nan,2,3\n0,1,0,2,2,3\nnan,1,1,2,2,3\n1,1,0,3,2,3\n');
  run(['view', f, '-o', path.join(dir, 'h.html'), '--title', title, '--quiet']);
  const html = fs.readFileSync(path.join(dir, 'h.html'), 'latin1');
  check(!html.includes('<script>alert') && !html.includes('<img/src=q') && !html.includes('</title><script>window'),
    'hostile: no name reaches the HTML as markup');
  await b.open('file://' + path.join(dir, 'h.html'), 20000);
  check((await b.eval('typeof window.__pwned')) === 'undefined', 'hostile: no injected script ran');
  check((await b.eval('document.getElementById("ttl").textContent')) === title, 'hostile: the title is shown as text');
  check((await b.eval('document.title')) === title + ' - jetfit view', 'hostile: <title> is the text');
  const opts = await b.eval('Array.from(document.querySelectorAll("#col option")).map(function(o){return o.textContent})');
  check(opts.includes('<img/src=q/onerror=__pwned=2>') && opts.includes('</script>'), 'hostile: column names are options, as text');
  check((await b.eval('document.getElementById("info").textContent')).includes('1 rows with missing x y z'), 'NaN x: said in the page');
  await b.eval('__jetfit.setColor("k1"); __jetfit.setPointSize(8); __jetfit.view("top")');
  const shot = await b.screenshot(), s = await b.eval('__jetfit.screenOfRow(1)');
  const txt = await b.eval(`__jetfit.click(${s[0]}, ${s[1]})`);
  check(/^row2 of 5/.test(txt) && /k1missing/.test(txt), `NaN k1: a click on it shows the row with k1 missing ("${txt.slice(0, 60)}...")`);
  check(dist(shot.at(s[0], s[1]), [0x7f, 0x7f, 0x7f]) <= 1, 'NaN k1: drawn in the missing grey');
}

async function large(b) {
  /* a wavy sheet of n points, written here as binary PLY */
  function write(n, file) {
    const hdr = `ply\nformat binary_little_endian 1.0\nelement vertex ${n}\n` +
      ['x', 'y', 'z', 'nx', 'ny', 'nz', 'k1', 'k2'].map((p) => `property float ${p}\n`).join('') + 'end_header\n';
    const d = Buffer.alloc(32 * n);
    let seed = 12345;
    const rnd = () => ((seed = (seed * 1103515245 + 12345) >>> 0) / 4294967296);
    for (let i = 0; i < n; i++) {
      const x = rnd() * 10, y = rnd() * 10, v = [x, y, 0.3 * Math.sin(x) * Math.cos(y), 0, 0, 1, -0.3 * Math.sin(x) * Math.cos(y), 0];
      v.forEach((a, k) => d.writeFloatLE(a, 32 * i + 4 * k));
    }
    fs.writeFileSync(file, Buffer.concat([Buffer.from(hdr), d]));
  }
  const N = 1000000;
  write(N, path.join(dir, 'big.ply'));
  write(1000, path.join(dir, 'small.ply'));
  let t0 = Date.now();
  run(['view', path.join(dir, 'big.ply'), '-o', path.join(dir, 'big.html'), '--quiet']);
  const tWrite = Date.now() - t0;
  run(['view', path.join(dir, 'small.ply'), '-o', path.join(dir, 'small.html'), '--quiet']);
  const per = (fs.statSync(path.join(dir, 'big.html')).size - fs.statSync(path.join(dir, 'small.html')).size) / (N - 1000);
  check(per < 40, `${per.toFixed(1)} bytes per drawn point (x y z, normal, k1, k2)`);
  t0 = Date.now();
  await b.open('file://' + path.join(dir, 'big.html'), 120000);
  const ready = Date.now() - t0, ff = await b.eval('__jetfit.firstFrameMs');
  check((await b.eval('__jetfit.ndrawn')) === N, '10^6 points: all drawn');
  t0 = Date.now();
  await b.eval('__jetfit.view("3d"); __jetfit.setColor("k2"); __jetfit.view("top")');
  const turn = Date.now() - t0;
  console.log(`time: jetfit view wrote 10^6 points in ${tWrite} ms; first frame ${ff.toFixed(0)} ms after navigation ` +
    `(page ready seen at ${ready} ms); recolour + two view changes ${turn} ms (SwiftShader, not asserted)`);
  /* --max-points: a spatially even subsample, said in the page */
  run(['view', path.join(dir, 'big.ply'), '-o', path.join(dir, 'sub.html'), '--max-points', '100000', '--quiet']);
  await b.open('file://' + path.join(dir, 'sub.html'), 60000);
  check((await b.eval('__jetfit.ndrawn')) === 100000, '--max-points 100000: 100000 drawn');
  check(/subsample: 100000 of the 1000000/.test(await b.eval('document.getElementById("info").textContent')), '--max-points: said in the page');
  const cells = await b.eval('(function(){var c=new Array(100).fill(0),n=__jetfit.ndrawn;for(var i=0;i<n;i++){var p=__jetfit.row(i).values.pos;' +
    'c[Math.min(9,Math.floor(p[0]))*10+Math.min(9,Math.floor(p[1]))]++;}return c;})()');
  check(Math.min(...cells) > 500 && Math.max(...cells) < 1500, `--max-points: every 1x1 cell of the 10x10 sheet holds ${Math.min(...cells)}..${Math.max(...cells)} of the 100000 (1000 even; within a factor 1.5)`);
}

(async () => {
  const b = await launch(chrome, W, H);
  try {
    if (mode === 'colours') await colours(b);
    else if (mode === 'hostile') await hostile(b);
    else if (mode === 'large') await large(b);
    else throw new Error('mode: colours | hostile | large');
  } catch (e) {
    console.log('FAIL ' + (e.stack || e));
    failures++;
  } finally {
    await b.close();
    fs.rmSync(dir, { recursive: true, force: true });
  }
  console.log(failures ? `${failures} failed` : 'all passed');
  process.exit(failures ? 1 : 0);
})();
