// lazperf_floats.js -- laz-perf (npm, WASM) decodes a .laz that jetfit
// wrote with float columns and checks its records against the .las of the
// same run with double columns: every Extra Byte a float in the .laz and a
// double in the .las (LAS 1.4 R15 table 24: types 9 and 10) holds
// Math.fround of the double (NaN for NaN) -- or, for a unit vector's
// component (nx ny nz d1x ... d2z) under `compact`, a whole number of 2^-16
// within 2^-17 of the double; every other byte -- the input's records, the
// integer columns -- is the same.  Both files' Extra Bytes
// VLRs are read here, from the headers, independently of jetfit.
// usage: node lazperf_floats.js NODE_MODULES OUT.laz OUT.las [compact]
// Exit 0 with a line of counts, 1 on a difference (message on stderr).
'use strict';
const fs = require('fs');
const path = require('path');
const [, , modules, lazPath, lasPath, mode] = process.argv;
const UNIT = /^(n[xyz]|d[12][xyz])$/;
const { createLazPerf } = require(path.join(modules, 'laz-perf'));
const BASE = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67];
const EBSIZE = [0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8];

// [{at, size, type}] of the Extra Bytes of a LAS/LAZ file's header
function extraBytes(b) {
  const hsize = b.readUInt16LE(94), nvlr = b.readUInt32LE(100);
  let at = BASE[b[104] & 0x3f], p = hsize;
  const out = [];
  for (let v = 0; v < nvlr; v++) {
    const len = b.readUInt16LE(p + 20);
    if (b.toString('latin1', p + 2, p + 11) === 'LASF_Spec' && b.readUInt16LE(p + 18) === 4) {
      for (let d = p + 54; d + 192 <= p + 54 + len; d += 192) {
        // 0: `options` undocumented bytes; 11-30: the deprecated 2- and 3-vectors
        const type = b[d + 2], size = type === 0 ? b[d + 3] : type <= 10 ? EBSIZE[type]
          : EBSIZE[(type - 11) % 10 + 1] * (type <= 20 ? 2 : 3);
        const name = b.toString('latin1', d + 4, d + 36).replace(/\0.*$/s, '');
        out.push({ at, size, type, name });
        at += size;
      }
    }
    p += 54 + len;
  }
  return out;
}

(async () => {
  const lp = await createLazPerf();
  const z = fs.readFileSync(lazPath), s = fs.readFileSync(lasPath);
  const ez = extraBytes(z), es = extraBytes(s);
  if (ez.length !== es.length) throw new Error(`${ez.length} Extra Bytes, the .las has ${es.length}`);
  const src = lp._malloc(z.length);
  lp.HEAPU8.set(z, src);
  const laz = new lp.LASZip();
  laz.open(src, z.length);
  const n = laz.getCount(), zlen = laz.getPointLength();
  const slen = s.readUInt16LE(105), sdata = s.readUInt32LE(96);
  const one = lp._malloc(zlen);
  let floats = 0, units = 0;
  for (let i = 0; i < n; i++) {
    laz.getPoint(one);
    const r = Buffer.from(lp.HEAPU8.subarray(one, one + zlen));
    const t = s.subarray(sdata + i * slen, sdata + (i + 1) * slen);
    const base = ez.length ? ez[0].at : zlen;
    if (Buffer.compare(r.subarray(0, base), t.subarray(0, base)) !== 0)
      throw new Error(`point ${i}: the point format's fields differ`);
    for (let k = 0; k < ez.length; k++) {
      const a = ez[k], c = es[k];
      if (a.type === 9 && c.type === 10) {
        const dbl = t.readDoubleLE(c.at), got = r.readFloatLE(a.at);
        if (mode === 'compact' && UNIT.test(a.name)) {
          const q = got * 65536;
          if (!(q === Math.floor(q) && Math.abs(got - dbl) <= 2 ** -17) &&
              !(got !== got && dbl !== dbl))
            throw new Error(`point ${i}: ${a.name}: float ${got} for ${dbl}: not the nearest multiple of 2^-16`);
          units++;
        } else {
          const want = Math.fround(dbl);
          if (!(got === want || (got !== got && want !== want)))
            throw new Error(`point ${i}: ${a.name}: float ${got}, fround of the double ${want}`);
          floats++;
        }
      } else if (a.type !== c.type || Buffer.compare(r.subarray(a.at, a.at + a.size),
                                                     t.subarray(c.at, c.at + c.size)) !== 0) {
        throw new Error(`point ${i}: Extra Byte ${k} (type ${a.type}) differs`);
      }
    }
  }
  laz.delete();
  lp._free(one);
  lp._free(src);
  if (!floats || (mode === 'compact' && !units)) throw new Error('no float or unit column');
  console.log(`lazperf_floats: ${lazPath}: ${n} points, ${floats} floats = fround(double), ` +
              `${units} unit components to 2^-16`);
})().catch((e) => {
  process.stderr.write(`lazperf_floats: ${lazPath}: ${e.message || e}\n`);
  process.exit(1);
});
