/* cdp.js -- a headless Chromium driven over the DevTools protocol on a
 * pipe (--remote-debugging-pipe: JSON messages ending in NUL on fds 3/4),
 * and a PNG decoder for its screenshots (RFC 2083: zlib, five filters).
 * Used by view_check.js; needs only node's standard library. */
'use strict';
const { spawn } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');
const zlib = require('zlib');

function findChromium() {
  for (const p of [process.env.CHROMIUM, '/usr/bin/chromium', '/usr/bin/chromium-browser'])
    if (p && fs.existsSync(p)) return p;
  return null;
}

async function launch(bin, width, height) {
  const prof = fs.mkdtempSync(path.join(os.tmpdir(), 'jf_view_chrome_'));
  const args = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    '--disable-default-apps', '--mute-audio', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    '--remote-debugging-pipe', `--user-data-dir=${prof}`, `--window-size=${width},${height}`, 'about:blank'];
  const ch = spawn(bin, args, { stdio: ['ignore', 'ignore', 'pipe', 'pipe', 'pipe'] });
  let stderr = '';
  ch.stdio[2].on('data', (d) => { stderr += d; });
  const out = ch.stdio[3], inp = ch.stdio[4];
  let id = 0, buf = Buffer.alloc(0);
  const waiting = new Map(), listeners = [];
  inp.on('data', (d) => {
    buf = Buffer.concat([buf, d]);
    let z;
    while ((z = buf.indexOf(0)) >= 0) {
      const msg = JSON.parse(buf.subarray(0, z).toString('utf8'));
      buf = buf.subarray(z + 1);
      if (msg.id !== undefined && waiting.has(msg.id)) {
        const w = waiting.get(msg.id);
        waiting.delete(msg.id);
        if (msg.error) w.reject(new Error(JSON.stringify(msg.error))); else w.resolve(msg.result);
      } else {
        for (const l of listeners) l(msg);
      }
    }
  });
  const dead = new Promise((res) => ch.on('exit', (code) => res(code)));
  function send(method, params, sessionId) {
    const m = { id: ++id, method, params: params || {} };
    if (sessionId) m.sessionId = sessionId;
    out.write(JSON.stringify(m) + '\0');
    return new Promise((resolve, reject) => {
      waiting.set(m.id, { resolve, reject });
      dead.then(() => reject(new Error('chromium exited: ' + stderr.slice(-2000))));
    });
  }
  const targets = await send('Target.getTargets');
  const page = targets.targetInfos.find((t) => t.type === 'page');
  const { sessionId } = await send('Target.attachToTarget', { targetId: page.targetId, flatten: true });
  const s = (m, p) => send(m, p, sessionId);
  const events = [];
  listeners.push((msg) => { if (msg.sessionId === sessionId) events.push(msg); });
  await s('Page.enable');
  await s('Runtime.enable');
  await s('Network.enable');
  await s('Log.enable');
  await s('Emulation.setDeviceMetricsOverride', { width, height, deviceScaleFactor: 1, mobile: false });
  return {
    send: s, events,
    async close() {
      try { await send('Browser.close'); } catch (e) { /* exiting */ }
      await Promise.race([dead, new Promise((r) => setTimeout(r, 3000))]);
      if (ch.exitCode === null) ch.kill('SIGKILL');
      fs.rmSync(prof, { recursive: true, force: true });
    },
    async eval(expr) {
      const r = await s('Runtime.evaluate', { expression: expr, returnByValue: true, awaitPromise: true });
      if (r.exceptionDetails) throw new Error('page: ' + JSON.stringify(r.exceptionDetails).slice(0, 800));
      return r.result.value;
    },
    async open(url, timeoutMs) {
      events.length = 0;
      await s('Page.navigate', { url });
      const t0 = Date.now();
      for (;;) {
        const st = await this.eval('window.__jetfit ? 1 : 0').catch(() => 0);
        if (st) return;
        const ex = events.find((e) => e.method === 'Runtime.exceptionThrown');
        if (ex) throw new Error('page error: ' + JSON.stringify(ex.params.exceptionDetails).slice(0, 1500));
        if (Date.now() - t0 > timeoutMs) throw new Error('the page did not get ready in ' + timeoutMs + ' ms');
        await new Promise((r) => setTimeout(r, 50));
      }
    },
    async screenshot() {
      const r = await s('Page.captureScreenshot', { format: 'png' });
      return decodePNG(Buffer.from(r.data, 'base64'));
    },
  };
}

/* 8-bit RGB or RGBA, non-interlaced: what Chromium writes */
function decodePNG(b) {
  let p = 8, w = 0, h = 0, ct = 0, idat = [];
  while (p < b.length) {
    const len = b.readUInt32BE(p), type = b.toString('ascii', p + 4, p + 8), d = b.subarray(p + 8, p + 8 + len);
    if (type === 'IHDR') {
      w = d.readUInt32BE(0); h = d.readUInt32BE(4); ct = d[9];
      if (d[8] !== 8 || (ct !== 2 && ct !== 6) || d[12] !== 0) throw new Error('unexpected PNG kind');
    } else if (type === 'IDAT') idat.push(d);
    p += 12 + len;
  }
  const raw = zlib.inflateSync(Buffer.concat(idat)), bpp = ct === 6 ? 4 : 3, stride = w * bpp;
  const px = Buffer.alloc(w * h * 3), prev = Buffer.alloc(stride), cur = Buffer.alloc(stride);
  for (let y = 0; y < h; y++) {
    const f = raw[y * (stride + 1)], line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; x++) {
      const a = x >= bpp ? cur[x - bpp] : 0, u = prev[x], c = x >= bpp ? prev[x - bpp] : 0;
      let v = line[x];
      if (f === 1) v += a; else if (f === 2) v += u; else if (f === 3) v += (a + u) >> 1;
      else if (f === 4) { const pp = a + u - c, pa = Math.abs(pp - a), pb = Math.abs(pp - u), pc = Math.abs(pp - c);
        v += pa <= pb && pa <= pc ? a : pb <= pc ? u : c; }
      cur[x] = v & 255;
    }
    for (let x = 0; x < w; x++) for (let k = 0; k < 3; k++) px[3 * (y * w + x) + k] = cur[x * bpp + k];
    cur.copy(prev);
  }
  return { w, h, at(x, y) { x = Math.round(x - 0.5); y = Math.round(y - 0.5); const i = 3 * (y * w + x); return [px[i], px[i + 1], px[i + 2]]; } };
}

module.exports = { findChromium, launch, decodePNG };
