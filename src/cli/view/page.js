/* page.js -- jetfit view's page (docs/view.md): decodes the columns that
 * view_write.c packed, draws the points with three.js, colours them by a
 * column through one 256-entry table shared by the points and the colour
 * bar, and answers clicks with the point's row.  Every name from the file
 * reaches the page through textContent, never as markup. */
(function () {
  'use strict';
  var T0 = performance.now();
  var meta = JSON.parse(document.getElementById('jf-meta').textContent);
  function bytes(id) {
    var s = atob(document.getElementById(id).textContent), n = s.length, u = new Uint8Array(n);
    for (var i = 0; i < n; i++) u[i] = s.charCodeAt(i);
    return u;
  }
  /* IEEE 754 half -> float, for every 16-bit pattern */
  var HALF = new Float32Array(65536);
  for (var h = 0; h < 65536; h++) {
    var e = h >> 10 & 31, f = h & 1023, s = h & 32768 ? -1 : 1;
    HALF[h] = e === 0 ? s * f * Math.pow(2, -24) : e === 31 ? (f ? NaN : s * Infinity)
      : s * (1 + f / 1024) * Math.pow(2, e - 15);
  }
  var rowsRaw = bytes('jf-rows');
  var M = meta.ndrawn;
  var ROWS = new Uint32Array(rowsRaw.buffer, 0, M);
  var cols = meta.columns, byName = {};
  cols.forEach(function (c, k) { c.raw = bytes('jf-c' + k); byName[c.name] = c; });

  /* one value of column c at drawn point i, in double precision */
  function value(c, i) {
    var r = c.raw, b = c.bytes * i;
    switch (c.enc) {
      case 'f16': return HALF[r[b] | r[b + 1] << 8] * c.scale;
      case 'log16': return Math.pow(2, HALF[r[b] | r[b + 1] << 8]);
      case 'u8': return r[b] === 255 ? NaN : c.off + r[b];
      case 'u16': var q = r[b] | r[b + 1] << 8; return q === 65535 ? NaN : c.off + q;
      case 'u32': var w = (r[b] | r[b + 1] << 8 | r[b + 2] << 16) + r[b + 3] * 16777216;
        return w === 4294967295 ? NaN : c.off + w;
    }
    return NaN;
  }
  function vec(c, i) { /* pos: x y z; oct: a unit vector */
    var r = c.raw, b = c.bytes * i;
    if (c.enc === 'pos') {
      var o = [];
      for (var d = 0; d < 3; d++) {
        var q = r[b + 2 * d] | r[b + 2 * d + 1] << 8;
        o.push(q === 65535 ? NaN : c.lo[d] + (c.hi[d] - c.lo[d]) * q / 65534);
      }
      return o;
    }
    var x = (r[b] << 24 >> 24), y = (r[b + 1] << 24 >> 24);
    if (x === -128) return [NaN, NaN, NaN];
    x /= 127; y /= 127;
    var z = 1 - Math.abs(x) - Math.abs(y);
    if (z < 0) { var ox = x; x = (1 - Math.abs(y)) * (x >= 0 ? 1 : -1); y = (1 - Math.abs(ox)) * (y >= 0 ? 1 : -1); }
    var l = Math.sqrt(x * x + y * y + z * z);
    return [x / l, y / l, z / l];
  }
  var cache = {};
  /* the colourable quantities: every scalar column, H and K from k1 k2 */
  var quant = [];
  cols.forEach(function (c) {
    if (c.enc !== 'pos' && c.enc !== 'oct')
      quant.push({name: c.name, unit: c.unit, log: c.enc === 'log16', get: function (i) { return value(c, i); }});
  });
  if (byName.k1 && byName.k2) {
    quant.push({name: 'mean', label: 'mean H = (k1+k2)/2', unit: '1/u', get: function (i) { return 0.5 * (value(byName.k1, i) + value(byName.k2, i)); }});
    quant.push({name: 'gauss', label: 'Gaussian K = k1 k2', unit: '1/u^2', get: function (i) { return value(byName.k1, i) * value(byName.k2, i); }});
  }
  var rgbCols = ['red', 'green', 'blue'].map(function (n) { return byName[n]; });
  var hasRGB = rgbCols[0] && rgbCols[1] && rgbCols[2];
  function values(q) {
    if (!cache[q.name]) {
      var a = new Float64Array(M);
      for (var i = 0; i < M; i++) a[i] = q.get(i);
      var fin = a.filter(function (v) { return isFinite(v); });
      if (q.log) fin = fin.filter(function (v) { return v > 0; }).map(Math.log10);
      fin.sort();
      cache[q.name] = {v: a, sorted: fin};
    }
    return cache[q.name];
  }

  /* colour tables: viridis-like (as `jetfit render`), and for values of
   * both signs a diverging purple - light grey - green, symmetric about 0 */
  function lut(stops) {
    var t = new Uint8Array(768);
    for (var k = 0; k < 256; k++) {
      var x = k / 255 * (stops.length - 1), j = Math.min(Math.floor(x), stops.length - 2), f = x - j;
      for (var c = 0; c < 3; c++)
        t[3 * k + c] = Math.round(stops[j][c] * (1 - f) + stops[j + 1][c] * f);
    }
    return t;
  }
  var SEQ = lut([[0x44, 0x01, 0x54], [0x3b, 0x52, 0x8b], [0x21, 0x91, 0x8c], [0x5e, 0xc9, 0x62], [0xfd, 0xe7, 0x25]]);
  var DIV = lut([[0x76, 0x2a, 0x83], [0xf2, 0xf2, 0xf2], [0x1b, 0x78, 0x37]]);
  var MISSING = [0x7f, 0x7f, 0x7f];

  /* ---- the scene ---- */
  var box = byName.pos, ctr = [0, 1, 2].map(function (d) { return 0.5 * (box.lo[d] + box.hi[d]); });
  var P = new Float32Array(3 * M); /* centred: float32 keeps offsets of 1e6 */
  for (var i = 0; i < M; i++) {
    var p = vec(box, i);
    for (var d = 0; d < 3; d++) P[3 * i + d] = p[d] - ctr[d];
  }
  var diag = Math.sqrt([0, 1, 2].reduce(function (s, d) { var w = box.hi[d] - box.lo[d]; return s + w * w; }, 0)) || 1;
  var view = document.getElementById('view');
  var renderer = new THREE.WebGLRenderer({antialias: false, preserveDrawingBuffer: true});
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xffffff, 1);
  view.appendChild(renderer.domElement);
  var scene = new THREE.Scene();
  var camera = new THREE.PerspectiveCamera(40, 1, diag * 1e-3, diag * 100);
  camera.up.set(0, 0, 1);
  var controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.screenSpacePanning = true;
  var geom = new THREE.BufferGeometry();
  var mat = new THREE.PointsMaterial({size: 2, sizeAttenuation: false, vertexColors: THREE.VertexColors});
  var points = new THREE.Points(geom, mat);
  scene.add(points);
  var visible = new Uint32Array(M), nvis = 0, COL = new Uint8Array(3 * M);

  var state = {q: null, lo: 0, hi: 1, diverging: false, plo: 2, phi: 98, flags: []};
  function quantile(s, p) {
    if (!s.length) return NaN;
    var x = p / 100 * (s.length - 1), j = Math.floor(x), f = x - j;
    return j + 1 < s.length ? s[j] * (1 - f) + s[j + 1] * f : s[j];
  }
  function setRange() {
    var q = state.q;
    if (!q || q === 'rgb') return;
    var s = values(q).sorted, lo = quantile(s, state.plo), hi = quantile(s, state.phi);
    if (!(lo <= hi)) lo = hi = 0;
    state.diverging = !q.log && lo < 0 && hi > 0;
    if (state.diverging) { hi = Math.max(-lo, hi); lo = -hi; }
    /* a constant column (a sphere's k1): below half precision, one colour */
    var mid = 0.5 * (lo + hi), tol = Math.max(Math.abs(lo), Math.abs(hi)) * 1e-3;
    if (hi - lo <= tol) { lo = mid - Math.max(tol, 1e-300); hi = mid + Math.max(tol, 1e-300); }
    state.lo = lo; state.hi = hi;
  }
  function entry(v) { /* the table entry of value v, -1 when missing */
    var q = state.q;
    if (!q || q === 'rgb') return -1;
    if (q.log) v = v > 0 ? Math.log10(v) : NaN;
    if (!isFinite(v)) return v === Infinity ? 255 : v === -Infinity ? 0 : -1;
    var t = (v - state.lo) / (state.hi - state.lo);
    return Math.round(Math.min(1, Math.max(0, t)) * 255);
  }
  function colorOf(v) {
    var k = entry(v), t = state.diverging ? DIV : SEQ;
    return k < 0 ? MISSING.slice() : [t[3 * k], t[3 * k + 1], t[3 * k + 2]];
  }
  function colour() {
    var q = state.q;
    if (q === 'rgb') {
      var mx = 0; /* 8-bit colours, or 16-bit as LAS stores them */
      for (var k = 0; k < M; k++) for (var c0 = 0; c0 < 3; c0++) { var x = value(rgbCols[c0], k); if (x > mx) mx = x; }
      var sc = mx > 255 ? 255 / 65535 : 1;
      for (var i = 0; i < M; i++)
        for (var c = 0; c < 3; c++) { var v = value(rgbCols[c], i); COL[3 * i + c] = isFinite(v) ? Math.round(v * sc) : 127; }
    } else if (!q) {
      COL.fill(0x50);
    } else {
      var a = values(q).v;
      for (var j = 0; j < M; j++) {
        var rgb = colorOf(a[j]);
        COL[3 * j] = rgb[0]; COL[3 * j + 1] = rgb[1]; COL[3 * j + 2] = rgb[2];
      }
    }
    rebuild();
    drawBar();
  }
  function shown(i) {
    if (!state.flags.length) return true;
    var st = value(byName.status, i);
    for (var k = 0; k < state.flags.length; k++) {
      var b = state.flags[k];
      if (b < 0 ? st === 0 : (st & (1 << b)) !== 0) return true;
    }
    return false;
  }
  function rebuild() {
    nvis = 0;
    for (var i = 0; i < M; i++) if (shown(i)) visible[nvis++] = i;
    var pos = new Float32Array(3 * nvis), col = new Uint8Array(3 * nvis);
    for (var k = 0; k < nvis; k++) {
      var i3 = 3 * visible[k];
      pos[3 * k] = P[i3]; pos[3 * k + 1] = P[i3 + 1]; pos[3 * k + 2] = P[i3 + 2];
      col[3 * k] = COL[i3]; col[3 * k + 1] = COL[i3 + 1]; col[3 * k + 2] = COL[i3 + 2];
    }
    geom.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    geom.setAttribute('color', new THREE.BufferAttribute(col, 3, true));
    geom.computeBoundingSphere();
    render();
  }
  var $ = function (id) { return document.getElementById(id); };
  function fmt(v) {
    if (isNaN(v)) return 'missing';
    if (!isFinite(v) || v === 0) return String(v);
    var a = Math.abs(v);
    return a >= 1e5 || a < 1e-3 ? v.toExponential(3) : String(+v.toPrecision(4));
  }
  function drawBar() {
    var q = state.q, cv = $('bar'), g = cv.getContext('2d'), img = g.createImageData(256, 1), t = state.diverging ? DIV : SEQ;
    for (var k = 0; k < 256; k++) {
      img.data[4 * k] = t[3 * k]; img.data[4 * k + 1] = t[3 * k + 1]; img.data[4 * k + 2] = t[3 * k + 2]; img.data[4 * k + 3] = 255;
    }
    g.putImageData(img, 0, 0);
    var plain = q && q !== 'rgb';
    cv.style.visibility = $('barlab').style.visibility = plain ? 'visible' : 'hidden';
    if (!plain) return;
    $('blo').textContent = fmt(q.log ? Math.pow(10, state.lo) : state.lo);
    $('bhi').textContent = fmt(q.log ? Math.pow(10, state.hi) : state.hi);
    $('bunit').textContent = (q.label || q.name) + (q.unit ? ' [' + q.unit + ']' : '') + (q.log ? ', log scale' : '');
  }
  /* client pixel of the bar's entry for value v: what the bar promises */
  function barPixel(v) {
    var k = entry(v), r = $('bar').getBoundingClientRect();
    if (k < 0) return null;
    return [r.left + 1 + (k + 0.5) * (r.width - 2) / 256, r.top + r.height / 2];
  }

  /* glyphs: the first meta.glyphs drawn points, the most spread */
  var glyph = {}, G = Math.min(meta.glyphs, M), glen = 0.55 * diag / Math.sqrt(Math.max(G, 1));
  function makeGlyphs(name, col, centred) {
    var c = byName[name];
    if (!c) { $({normal: 'gn', d1: 'g1', d2: 'g2'}[name]).disabled = true; return; }
    var a = new Float32Array(6 * G), n = 0;
    for (var i = 0; i < G; i++) {
      var v = vec(c, i);
      if (!isFinite(v[0])) continue;
      var s0 = centred ? -0.5 : 0, s1 = centred ? 0.5 : 1;
      for (var d = 0; d < 3; d++) {
        a[6 * n + d] = P[3 * i + d] + s0 * glen * v[d];
        a[6 * n + 3 + d] = P[3 * i + d] + s1 * glen * v[d];
      }
      n++;
    }
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(a.subarray(0, 6 * n), 3));
    /* over the points: in the tangent plane they would fight the points' depth */
    var ls = new THREE.LineSegments(g, new THREE.LineBasicMaterial({color: col, depthTest: false}));
    ls.renderOrder = 1;
    ls.visible = false;
    scene.add(ls);
    glyph[name] = ls;
  }
  makeGlyphs('normal', 0x202020, false);
  makeGlyphs('d1', 0xe41a1c, true);
  makeGlyphs('d2', 0x1f4fd8, true);

  function render() { renderer.render(scene, camera); }
  function resize() {
    var w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    render();
  }
  function setView(name) {
    var dir = name === 'top' ? [0, 0, 1] : name === 'front' ? [0, -1, 0] : [0.55, -0.85, 0.6];
    var l = Math.sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    var dist = 0.5 * diag / Math.sin(camera.fov * Math.PI / 360) * 1.05;
    camera.up.set(0, name === 'top' ? 1 : 0, name === 'top' ? 0 : 1);
    camera.position.set(dir[0] / l * dist, dir[1] / l * dist, dir[2] / l * dist);
    controls.target.set(0, 0, 0);
    controls.update();
    render();
  }
  controls.addEventListener('change', render);

  /* picking: the nearest the eye among the points whose square covers the
   * pixel (what is drawn there), else the nearest on screen within 4 px */
  function screenOfDrawn(i) {
    var v = new THREE.Vector3(P[3 * i], P[3 * i + 1], P[3 * i + 2]).project(camera);
    var r = renderer.domElement.getBoundingClientRect();
    if (v.z < -1 || v.z > 1) return null;
    return [r.left + (v.x + 1) / 2 * r.width, r.top + (1 - v.y) / 2 * r.height, v.z];
  }
  function pick(x, y) {
    var r = renderer.domElement.getBoundingClientRect(), m = new THREE.Matrix4();
    m.multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse);
    var e = m.elements, half = mat.size / (window.devicePixelRatio || 1) / 2, rad = Math.max(4, half);
    var cover = -1, cz = Infinity, near = -1, nd = Infinity;
    for (var k = 0; k < nvis; k++) {
      var i = visible[k], px = P[3 * i], py = P[3 * i + 1], pz = P[3 * i + 2];
      var w = e[3] * px + e[7] * py + e[11] * pz + e[15];
      if (w <= 0) continue;
      var sx = r.left + ((e[0] * px + e[4] * py + e[8] * pz + e[12]) / w + 1) / 2 * r.width;
      var sy = r.top + (1 - (e[1] * px + e[5] * py + e[9] * pz + e[13]) / w) / 2 * r.height;
      var dx = sx - x, dy = sy - y, dd = dx * dx + dy * dy;
      if (dd > rad * rad) continue;
      var z = (e[2] * px + e[6] * py + e[10] * pz + e[14]) / w;
      if (Math.abs(dx) <= half && Math.abs(dy) <= half && z < cz) { cover = i; cz = z; }
      if (dd < nd) { near = i; nd = dd; }
    }
    var best = cover >= 0 ? cover : near;
    return best < 0 ? null : rowOf(best);
  }
  function flagNames(st) {
    if (st === 0) return 'ok';
    var n = [];
    for (var b = 0; b < 32; b++) if (st & (1 << b)) n.push(meta.flags[b] || 'bit ' + b);
    return n.join('|');
  }
  function rowOf(i) {
    var o = {row: ROWS[i], drawn: i, values: {}};
    cols.forEach(function (c) {
      if (c.enc === 'pos' || c.enc === 'oct') o.values[c.name] = vec(c, i);
      else o.values[c.name] = value(c, i);
    });
    return o;
  }
  function showRow(o) {
    var t = $('row');
    while (t.firstChild) t.removeChild(t.firstChild);
    function line(k, v) {
      var tr = document.createElement('tr'), a = document.createElement('td'), b = document.createElement('td');
      a.textContent = k; b.textContent = v; tr.appendChild(a); tr.appendChild(b); t.appendChild(tr);
    }
    if (!o) { line('', 'no point here'); return; }
    line('row', String(o.row + 1) + ' of ' + meta.nrows);
    cols.forEach(function (c) {
      var v = o.values[c.name];
      if (Array.isArray(v)) line({pos: 'x y z', normal: 'nx ny nz', d1: 'd1x d1y d1z', d2: 'd2x d2y d2z'}[c.name], v.map(fmt).join(' '));
      else line(c.name, c.name === 'status' && isFinite(v) ? v + ' (' + flagNames(v) + ')' : fmt(v));
    });
    if (byName.k1 && byName.k2) {
      line('mean H', fmt(0.5 * (o.values.k1 + o.values.k2)));
      line('Gaussian K', fmt(o.values.k1 * o.values.k2));
    }
  }
  var down = null;
  renderer.domElement.addEventListener('pointerdown', function (ev) { down = [ev.clientX, ev.clientY]; });
  renderer.domElement.addEventListener('pointerup', function (ev) {
    if (down && Math.abs(ev.clientX - down[0]) + Math.abs(ev.clientY - down[1]) < 4) showRow(pick(ev.clientX, ev.clientY));
    down = null;
  });

  /* ---- the panel ---- */
  $('ttl').textContent = meta.title;
  var info = M + ' of ' + meta.nrows + ' rows drawn';
  $('info').textContent = info + ' (' + meta.file + '; jetfit ' + meta.version + ', three.js ' + meta.three + ').';
  if (M < meta.nfinite) {
    var w = document.createElement('div');
    w.className = 'warn';
    w.textContent = 'A spatially even subsample: ' + M + ' of the ' + meta.nfinite +
      ' points (jetfit view --max-points ' + meta.maxPoints + ').';
    $('info').appendChild(w);
  }
  if (meta.nfinite < meta.nrows) {
    var w2 = document.createElement('div');
    w2.textContent = (meta.nrows - meta.nfinite) + ' rows with missing x y z are not drawn.';
    $('info').appendChild(w2);
  }
  var sel = $('col');
  function opt(value, text) { var o = document.createElement('option'); o.value = value; o.textContent = text; sel.appendChild(o); }
  quant.forEach(function (q, k) { opt(String(k), q.label || q.name); });
  if (hasRGB) opt('rgb', 'RGB (the input\'s colours)');
  opt('none', 'none');
  function setColor(name) {
    var k = -1;
    quant.forEach(function (q, j) { if (q.name === name) k = j; });
    state.q = name === 'rgb' && hasRGB ? 'rgb' : k >= 0 ? quant[k] : null;
    sel.value = state.q === 'rgb' ? 'rgb' : state.q ? String(k) : 'none';
    setRange();
    colour();
  }
  sel.addEventListener('change', function () {
    var v = sel.value;
    setColor(v === 'rgb' ? 'rgb' : v === 'none' ? '' : quant[+v].name);
  });
  function setClip(lo, hi) {
    state.plo = Math.max(0, Math.min(100, lo)); state.phi = Math.max(state.plo, Math.min(100, hi));
    $('plo').value = state.plo; $('phi').value = state.phi;
    setRange(); colour();
  }
  ['plo', 'phi'].forEach(function (id) {
    $(id).addEventListener('change', function () { setClip(+$('plo').value, +$('phi').value); });
  });
  /* the status flags present, as a filter */
  if (byName.status) {
    var any = 0, zero = false;
    for (var i2 = 0; i2 < M; i2++) { var st = value(byName.status, i2); if (st === 0) zero = true; else if (isFinite(st)) any |= st; }
    var bits = zero ? [-1] : [];
    for (var b = 0; b < 32; b++) if (any & (1 << b)) bits.push(b);
    bits.forEach(function (b) {
      var l = document.createElement('label'), c = document.createElement('input');
      c.type = 'checkbox'; c.value = String(b);
      c.addEventListener('change', function () {
        state.flags = Array.prototype.filter.call($('flags').querySelectorAll('input'), function (x) { return x.checked; })
          .map(function (x) { return +x.value; });
        rebuild();
      });
      l.appendChild(c);
      l.appendChild(document.createTextNode(' ' + (b < 0 ? 'ok (no flag)' : meta.flags[b] || 'bit ' + b)));
      $('flags').appendChild(l);
    });
  } else {
    $('flags').style.display = 'none';
  }
  function toggle(name, on) {
    var id = {normal: 'gn', d1: 'g1', d2: 'g2'}[name];
    if (!glyph[name]) return false;
    glyph[name].visible = !!on; $(id).checked = !!on;
    render();
    return true;
  }
  [['gn', 'normal'], ['g1', 'd1'], ['g2', 'd2']].forEach(function (p) {
    $(p[0]).addEventListener('change', function () { toggle(p[1], $(p[0]).checked); });
  });
  function setPointSize(s) { mat.size = s; $('psize').value = s; render(); }
  $('psize').addEventListener('input', function () { setPointSize(+$('psize').value); });
  window.addEventListener('resize', resize);

  resize();
  setView('3d');
  var start = meta.color && (meta.color === 'rgb' || quant.some(function (q) { return q.name === meta.color; })) ? meta.color : '';
  setColor(start);
  /* the first frame is on screen once the GPU has finished it */
  var gl = renderer.getContext();
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  var firstFrameMs = performance.now();

  /* a small hook for the tests (tests/view/view_check.js) */
  window.__jetfit = {
    ready: true, firstFrameMs: firstFrameMs, scriptMs: firstFrameMs - T0, ndrawn: M, nvisible: function () { return nvis; },
    click: function (x, y) { showRow(pick(x, y)); return $('row').textContent; },
    setColor: setColor, setClip: setClip, toggle: toggle, view: setView, pick: pick, colorOf: colorOf,
    barPixel: barPixel, setPointSize: setPointSize, range: function () { return [state.lo, state.hi, state.diverging]; },
    setFlags: function (f) { state.flags = f.slice(); rebuild(); },
    screenOfRow: function (row) { for (var i = 0; i < M; i++) if (ROWS[i] === row) return screenOfDrawn(i); return null; },
    screenOfDrawn: screenOfDrawn, row: rowOf, rows: function () { return Array.from(ROWS); }
  };
})();
