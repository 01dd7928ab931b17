// lazperf_bench.js -- laz-perf's (npm, WASM) decoding speed on one file,
// for bench_laz: decodes every point of IN.laz R times and prints
// "lazperf SECONDS_PER_PASS CPU_SECONDS POINTS".  usage: node lazperf_bench.js NODE_MODULES IN.laz R
'use strict';
const fs = require('fs');
const path = require('path');
const [, , modules, input, reps] = process.argv;
const { createLazPerf } = require(path.join(modules, 'laz-perf'));
(async () => {
  const lp = await createLazPerf();
  const bytes = fs.readFileSync(input);
  const src = lp._malloc(bytes.length);
  lp.HEAPU8.set(bytes, src);
  let best = Infinity, bestCpu = 0, n = 0;
  for (let r = 0; r < Number(reps); r++) {
    const t = process.hrtime.bigint(), c = process.cpuUsage();
    const laz = new lp.LASZip();
    laz.open(src, bytes.length);
    n = laz.getCount();
    const one = lp._malloc(laz.getPointLength());
    for (let i = 0; i < n; i++) laz.getPoint(one);
    lp._free(one);
    laz.delete();
    const s = Number(process.hrtime.bigint() - t) / 1e9;
    const u = process.cpuUsage(c);
    if (s < best) { best = s; bestCpu = (u.user + u.system) / 1e6; }
  }
  console.log(`lazperf ${best} ${bestCpu} ${n}`);
})().catch((e) => { process.stderr.write(`lazperf_bench: ${e}\n`); process.exit(1); });
