#!/usr/bin/env python3
"""las_numpy_check.py JETFIT INPUT DIR -- a second, independent LAS reader
(numpy only, written from the LAS 1.4 R15 text) checks `jetfit estimate
INPUT -o DIR/out.las` against `jetfit estimate INPUT -o DIR/out.csv`:
the header (signature, version, counts, record length, scale/offset),
the Extra Bytes VLR (a name per column, its type), and every value: the
jetfit columns bit for bit, x y z within half a scale step.
When INPUT is a LAS file, also that the output keeps it (issue 13.2):
same point format, scale, offset, bounds and system identifier, the
input's VLRs copied, every input record byte unchanged at the start of
its output record, x y z exactly the input's, the input's dimensions
(decoded here from the bits) equal to the CSV's columns of the same name.
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
os.makedirs(out, exist_ok=True)
las, csv = os.path.join(out, "out.las"), os.path.join(out, "out.csv")
for o in (las, csv):
    subprocess.run([jetfit, "estimate", src, "-o", o, "--quiet"], check=True)

EB_TYPES = {1: "<u1", 2: "<i1", 3: "<u2", 4: "<i2", 5: "<u4", 6: "<i4", 7: "<u8", 8: "<i8",
            9: "<f4", 10: "<f8"}
BASE_LEN = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67]


def header(b):
    """The public header block's fields this check uses."""
    if b[:4] != b"LASF":
        fail("no LASF signature")
    h = {"major": b[24], "minor": b[25]}
    h["hsize"], = struct.unpack_from("<H", b, 94)
    h["data_off"], h["nvlr"] = struct.unpack_from("<II", b, 96)
    h["fmt"] = b[104] & 0x3F
    h["rec_len"], = struct.unpack_from("<H", b, 105)
    h["legacy"], = struct.unpack_from("<I", b, 107)
    h["n"] = h["legacy"]
    if h["minor"] >= 4:
        n64, = struct.unpack_from("<Q", b, 247)
        h["n"] = n64 or h["legacy"]
    h["scale"] = struct.unpack_from("<3d", b, 131)
    h["offset"] = struct.unpack_from("<3d", b, 155)
    h["bounds"] = b[179:227]
    h["system"] = b[26:58]
    return h


def vlrs(b, h):
    """[(user_id, record_id, payload bytes, whole record bytes)]"""
    out, p = [], h["hsize"]
    for _ in range(h["nvlr"]):
        user = b[p + 2:p + 18].rstrip(b"\0").decode("latin-1")
        rid, after = struct.unpack_from("<HH", b, p + 18)
        out.append((user, rid, b[p + 54:p + 54 + after], b[p:p + 54 + after]))
        p += 54 + after
    if p != h["data_off"]:
        fail("VLRs end at %d, point data at %d" % (p, h["data_off"]))
    return out


def extra_bytes(vl):
    """Names and numpy types of the Extra Bytes descriptions."""
    eb = [v for v in vl if v[0] == "LASF_Spec" and v[1] == 4]
    if len(eb) > 1:
        fail("%d Extra Bytes VLRs" % len(eb))
    fields = []
    for k in range(len(eb[0][2]) // 192 if eb else 0):
        d = eb[0][2][192 * k:192 * (k + 1)]
        dt = d[2]
        name = d[4:36].rstrip(b"\0").decode("latin-1")
        if dt == 0:
            fields.append(("undocumented%d" % k, "V%d" % d[3]))
        elif dt in EB_TYPES:
            fields.append((name, EB_TYPES[dt]))
        else:
            fail("extra byte %s has data type %d" % (name, dt))
    return fields


def decode_dims(r, fmt):
    """The standard dimensions of records r (a (n, rec_len) uint8 array),
    decoded from the spec's tables: name -> values."""
    le = lambda off, t: r[:, off:off + np.dtype(t).itemsize].copy().view(t).ravel()
    d = {"intensity": le(12, "<u2")}
    if fmt < 6:
        b14, b15 = r[:, 14], r[:, 15]
        d.update(return_number=b14 & 7, number_of_returns=(b14 >> 3) & 7,
                 scan_direction_flag=(b14 >> 6) & 1, edge_of_flight_line=b14 >> 7,
                 classification=b15 & 31, synthetic=(b15 >> 5) & 1, key_point=(b15 >> 6) & 1,
                 withheld=b15 >> 7, scan_angle_rank=le(16, "<i1"), user_data=r[:, 17],
                 point_source_id=le(18, "<u2"))
        gps, rgb = {1: 20, 3: 20, 4: 20, 5: 20}.get(fmt), {2: 20, 3: 28, 5: 28}.get(fmt)
    else:
        b14, b15 = r[:, 14], r[:, 15]
        d.update(return_number=b14 & 15, number_of_returns=b14 >> 4, synthetic=b15 & 1,
                 key_point=(b15 >> 1) & 1, withheld=(b15 >> 2) & 1, overlap=(b15 >> 3) & 1,
                 scanner_channel=(b15 >> 4) & 3, scan_direction_flag=(b15 >> 6) & 1,
                 edge_of_flight_line=b15 >> 7, classification=r[:, 16], user_data=r[:, 17],
                 scan_angle=le(18, "<i2"), point_source_id=le(20, "<u2"))
        gps, rgb = 22, {7: 30, 8: 30, 10: 30}.get(fmt)
    if gps is not None:
        d["gps_time"] = le(gps, "<f8")
    if rgb is not None:
        for k, c in enumerate(("red", "green", "blue")):
            d[c] = le(rgb + 2 * k, "<u2")
    if fmt in (8, 10):
        d["nir"] = le(36, "<u2")
    return d


b = open(las, "rb").read()
h = header(b)
if (h["major"], h["minor"]) != (1, 4):
    fail("version %d.%d, want 1.4" % (h["major"], h["minor"]))
n = h["n"]
vl = vlrs(b, h)
eb = extra_bytes(vl)
ref = np.genfromtxt(csv, delimiter=",", names=True)
if len(ref) != n:
    fail("%d points in the LAS file, %d rows in the CSV" % (n, len(ref)))
cols = list(ref.dtype.names)
jetfit_cols = cols[cols.index("nx"):]

src_las = src.lower().endswith(".las")
if src_las:
    ib = open(src, "rb").read()
    ih = header(ib)
    ivl = vlrs(ib, ih)
    for key in ("fmt", "scale", "offset", "bounds", "system"):
        if h[key] != ih[key]:
            fail("%s: %r in the output, %r in the input" % (key, h[key], ih[key]))
    if h["hsize"] != 375 or (h["fmt"] < 6 and h["legacy"] != n) or n != ih["n"]:
        fail("header size %d, legacy count %d, %d points (input %d)"
             % (h["hsize"], h["legacy"], n, ih["n"]))
    kept = [v[3] for v in ivl if not (v[0] == "LASF_Spec" and v[1] == 4)]
    if [v[3] for v in vl if not (v[0] == "LASF_Spec" and v[1] == 4)] != kept:
        fail("the input's VLRs are not copied unchanged")
    irec = np.frombuffer(ib, dtype=np.uint8, count=n * ih["rec_len"],
                         offset=ih["data_off"]).reshape(n, ih["rec_len"])
    orec = np.frombuffer(b, dtype=np.uint8, count=n * h["rec_len"],
                         offset=h["data_off"]).reshape(n, h["rec_len"])
    if not (orec[:, :ih["rec_len"]] == irec).all():
        i = int(np.argmin((orec[:, :ih["rec_len"]] == irec).all(axis=1)))
        fail("record %d differs from the input's" % i)
    base = [("X", "<i4"), ("Y", "<i4"), ("Z", "<i4"),
            ("rest", "V%d" % (BASE_LEN[h["fmt"]] - 12))]
    dims = decode_dims(irec, ih["fmt"])
    for name, v in dims.items():
        if name not in cols:
            fail("dimension %s is not in the CSV output" % name)
        if not (v.astype(np.float64) == ref[name]).all():
            fail("dimension %s differs from the CSV's" % name)
    nkept = len(eb) - len(jetfit_cols)
    if [f[0] for f in eb[nkept:]] != jetfit_cols:
        fail("extra bytes end with %s, want %s" % ([f[0] for f in eb[nkept:]], jetfit_cols))
else:
    if h["hsize"] != 375 or h["fmt"] != 0 or h["nvlr"] != 1:
        fail("header size %d, format %d, %d VLRs" % (h["hsize"], h["fmt"], h["nvlr"]))
    if h["legacy"] != n:
        fail("legacy count %d, 64-bit count %d" % (h["legacy"], n))
    base = [("X", "<i4"), ("Y", "<i4"), ("Z", "<i4"), ("rest", "V8")]
    if [f[0] for f in eb] != cols[3:]:
        fail("extra bytes %s, CSV columns %s" % ([f[0] for f in eb], cols[3:]))

rec = np.dtype(base + eb)
if rec.itemsize != h["rec_len"]:
    fail("record length %d (descriptions give %d)" % (h["rec_len"], rec.itemsize))
pts = np.frombuffer(b, dtype=rec, count=n, offset=h["data_off"])
for name, _ in eb:
    if name.startswith("undocumented") or name not in cols:
        continue
    a = pts[name].astype(np.float64)
    r = ref[name]
    same = (a == r) | (np.isnan(a) & np.isnan(r))
    if not same.all():
        i = int(np.argmin(same))
        fail("%s row %d: %r in LAS, %r in CSV" % (name, i, a[i], r[i]))
for k, axis in enumerate("xyz"):
    v = pts["XYZ"[k]] * h["scale"][k] + h["offset"][k]
    err = np.abs(v - ref[axis])
    ok = np.isfinite(ref[axis])
    tol = 0 if src_las else 0.5 * h["scale"][k] * (1 + 1e-9)
    if (err[ok] > tol + (0 if src_las else 1e-12) * np.abs(ref[axis][ok])).any():
        fail("%s: %g off, scale %g" % (axis, err[ok].max(), h["scale"][k]))
print("las_numpy_check: %d points, format %d, %d extra bytes, all agree (scale %g %g %g)%s"
      % (n, h["fmt"], len(eb), *h["scale"],
         ", input records kept" if src_las else ""))
