#!/usr/bin/env python3
"""las_numpy_check.py JETFIT INPUT DIR -- a second, independent LAS reader
(numpy only, written from the LAS 1.4 R15 text) checks `jetfit estimate
INPUT -o DIR/out.las` against `jetfit estimate INPUT -o DIR/out.csv`:
the header (signature, version, counts, record length, scale/offset),
the Extra Bytes VLR (a name per jetfit column, double or int32), and every
value: the jetfit columns bit for bit, x y z within half a scale step.
Exit 0 when all agree, 1 with one line saying what differs, 77 (skip)
without numpy."""
import os
import struct
import subprocess
import sys

try:
    import numpy as np
except ImportError:
    print("skipped: numpy not installed")
    sys.exit(77)


def fail(msg):
    print("las_numpy_check: " + msg)
    sys.exit(1)


jetfit, src, out = sys.argv[1], sys.argv[2], sys.argv[3]
las, csv = os.path.join(out, "out.las"), os.path.join(out, "out.csv")
for o in (las, csv):
    subprocess.run([jetfit, "estimate", src, "-o", o, "--quiet"], check=True)

b = open(las, "rb").read()
if b[:4] != b"LASF":
    fail("no LASF signature")
if (b[24], b[25]) != (1, 4):
    fail("version %d.%d, want 1.4" % (b[24], b[25]))
hsize, = struct.unpack_from("<H", b, 94)
data_off, nvlr = struct.unpack_from("<II", b, 96)
fmt, rec_len, legacy = b[104], struct.unpack_from("<H", b, 105)[0], struct.unpack_from("<I", b, 107)[0]
scale = struct.unpack_from("<3d", b, 131)
offset = struct.unpack_from("<3d", b, 155)
n, = struct.unpack_from("<Q", b, 247)
if hsize != 375 or fmt != 0 or nvlr != 1:
    fail("header size %d, format %d, %d VLRs" % (hsize, fmt, nvlr))
if legacy != n:
    fail("legacy count %d, 64-bit count %d" % (legacy, n))

# the one VLR: LASF_Spec record 4, Extra Bytes descriptions
p = hsize
user = b[p + 2:p + 18].rstrip(b"\0").decode()
rec_id, after = struct.unpack_from("<HH", b, p + 18)
if user != "LASF_Spec" or rec_id != 4 or after % 192:
    fail("VLR %s/%d of %d bytes is not Extra Bytes" % (user, rec_id, after))
types = {10: "<f8", 6: "<i4", 9: "<f4"}
fields = [("X", "<i4"), ("Y", "<i4"), ("Z", "<i4"), ("rest", "V8")]
names = []
for k in range(after // 192):
    d = p + 54 + 192 * k
    dt = b[d + 2]
    name = b[d + 4:d + 36].rstrip(b"\0").decode()
    if dt not in types:
        fail("extra byte %s has data type %d" % (name, dt))
    fields.append((name, types[dt]))
    names.append(name)
rec = np.dtype(fields)
if rec.itemsize != rec_len or data_off != p + 54 + after:
    fail("record length %d (descriptions give %d), data at %d" % (rec_len, rec.itemsize, data_off))
pts = np.frombuffer(b, dtype=rec, count=n, offset=data_off)

ref = np.genfromtxt(csv, delimiter=",", names=True)
if len(ref) != n:
    fail("%d points in the LAS file, %d rows in the CSV" % (n, len(ref)))
if names != list(ref.dtype.names[3:]):
    fail("extra bytes %s, CSV columns %s" % (names, ref.dtype.names[3:]))
for name in names:
    a = pts[name].astype(np.float64)
    r = ref[name]
    same = (a == r) | (np.isnan(a) & np.isnan(r))
    if not same.all():
        i = int(np.argmin(same))
        fail("%s row %d: %r in LAS, %r in CSV" % (name, i, a[i], r[i]))
for k, axis in enumerate("xyz"):
    v = pts["XYZ"[k]] * scale[k] + offset[k]
    err = np.abs(v - ref[axis])
    ok = np.isfinite(ref[axis])
    if (err[ok] > 0.5 * scale[k] * (1 + 1e-9) + 1e-12 * np.abs(ref[axis][ok])).any():
        fail("%s: %g off, scale %g" % (axis, err[ok].max(), scale[k]))
print("las_numpy_check: %d points, %d extra bytes, all agree (scale %g %g %g)"
      % (n, len(names), *scale))
