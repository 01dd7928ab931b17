// lazperf_dump.js -- an independent LAZ decoder for the tests: laz-perf
// (npm, WASM) decodes IN.laz and writes its point records, concatenated,
// to OUT.  usage: node lazperf_dump.js NODE_MODULES IN.laz OUT [KEEP]
// (KEEP: only the first KEEP bytes of each record, e.g. the input's part
// of a record jetfit extended with its columns).
// Exit 0 on success, 1 on failure (message on stderr).
'use strict';
const fs = require('fs');
const path = require('path');
const [, , modules, input, output, keepArg] = process.argv;
const { createLazPerf } = require(path.join(modules, 'laz-perf'));

(async () => {
  const lp = await createLazPerf();
  const bytes = fs.readFileSync(input);
  const src = lp._malloc(bytes.length);
  lp.HEAPU8.set(bytes, src);
  const laz = new lp.LASZip();
  laz.open(src, bytes.length);
  const n = laz.getCount(), len = laz.getPointLength();
  const keep = keepArg ? Math.min(Number(keepArg), len) : len;
  const out = Buffer.alloc(n * keep);
  const one = lp._malloc(len);
  for (let i = 0; i < n; i++) {
    laz.getPoint(one);
    out.set(lp.HEAPU8.subarray(one, one + keep), i * keep);
  }
  fs.writeFileSync(output, out);
  laz.delete();
  lp._free(one);
  lp._free(src);
})().catch((e) => {
  process.stderr.write(`lazperf_dump: ${input}: ${e}\n`);
  process.exit(1);
});
