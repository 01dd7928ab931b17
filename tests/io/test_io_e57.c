/* test_io_e57.c -- the E57 reader (issue 26) on files no one here wrote
 * (libE57Format's test data, tests/data/e57/SOURCE.md): point counts and
 * bounds against what each file's own XML says (read here by string
 * search over pages stripped here, not by the reader's parser), the first
 * value of the cube decoded here by hand, the float and double cubes
 * equal; two-scan files written by tests/io/e57_write.h (Cartesian floats
 * with one pose, spherical scaled integers with another, invalid rows)
 * back in one frame within the encodings' rounding, every normal of a
 * sphere facing its own scanner; every damaged or lying file a one-line
 * FILE: reason, an empty cloud, and (command) exit status 1, no output;
 * the command's default orientation on E57 is each row's own scanner. */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "jetfit.h"

#include "e57_write.h"
#include "test_io_util.h"
#include "jf_test.h"

#define DATA JF_TESTS_DIR "/data/e57/"
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void setup(void) { tmpdir_setup("/tmp/jf_io_e57_XXXXXX"); }

/* The XML section, found by the header's offset and length, NUL
 * terminated (checksums dropped here, not by the reader). */
static char *logical(const char *path, size_t *n)
{
    size_t len;
    unsigned char *b = jf_test_slurp(path, &len);
    char *o = malloc(len + 1);
    size_t k = 0;
    for (size_t p = 0; p < len; p += 1024) {
        memcpy(o + k, b + p, 1020);
        k += 1020;
    }
    uint64_t xo = 0, xl = 0;
    for (int i = 7; i >= 0; i--) xo = xo << 8 | b[24 + i], xl = xl << 8 | b[32 + i];
    size_t at = (size_t)(xo / 1024 * 1020 + xo % 1024);
    ck_assert(at + xl <= k);
    memmove(o, o + at, (size_t)xl);
    o[xl] = 0;
    free(b);
    *n = (size_t)xl;
    return o;
}

/* The logical image (checksums dropped), for reading binary sections by hand. */
static unsigned char *image(const char *path)
{
    size_t len;
    unsigned char *b = jf_test_slurp(path, &len), *o = malloc(len);
    for (size_t p = 0, k = 0; p < len; p += 1024, k += 1020) memcpy(o + k, b + p, 1020);
    free(b);
    return o;
}

/* The number after `key` (e.g. "recordCount=\"" or "<xMinimum type=\"Float\">"). */
static double after(const char *text, const char *key)
{
    const char *p = strstr(text, key);
    ck_assert_msg(p != NULL, "no %s", key);
    return strtod(p + strlen(key), NULL);
}

static jf_cloud read_ok(const char *path)
{
    jf_cloud c;
    jf_error e = {{0}};
    ck_assert_msg(jf_cloud_read(path, NULL, &c, &e) == JF_OK, "%s", e.msg);
    return c;
}

static void bounds(const jf_cloud *c, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) lo[a] = INFINITY, hi[a] = -INFINITY;
    for (size_t i = 0; i < c->n; i++)
        for (int a = 0; a < 3; a++) {
            double v = c->xyz[3 * i + a];
            if (v < lo[a]) lo[a] = v;
            if (v > hi[a]) hi[a] = v;
        }
}

START_TEST(cubes_float_and_double)
{
    size_t ln;
    char *x = logical(DATA "ColouredCubeFloat.e57", &ln);
    size_t want = (size_t)after(x, "recordCount=\"");
    jf_cloud f = read_ok(DATA "ColouredCubeFloat.e57");
    jf_cloud d = read_ok(DATA "ColouredCubeDouble.e57");
    ck_assert_uint_eq(f.n, want);
    ck_assert_uint_eq(d.n, want);
    ck_assert_uint_eq(f.nscans, 1);
    for (int k = 0; k < 3; k++) ck_assert(f.scanner[k] == 0); /* no pose: the identity */
    /* the prototype says [-0.5, 0.5]; a cube's points reach every face */
    double lo[3], hi[3];
    bounds(&f, lo, hi);
    for (int a = 0; a < 3; a++) ck_assert(lo[a] == -0.5 && hi[a] == 0.5);
    /* by hand: section header at logical 48, first data packet, stream 0 */
    unsigned char *L = image(DATA "ColouredCubeFloat.e57");
    ck_assert_uint_eq(L[48], 1);
    uint64_t dp = 0;
    for (int k = 7; k >= 0; k--) dp = dp << 8 | L[48 + 16 + k];
    size_t p = (size_t)(dp / 1024 * 1020 + dp % 1024);
    ck_assert_uint_eq(L[p], 1);
    size_t nf = (size_t)(L[p + 4] | L[p + 5] << 8);
    ck_assert_uint_eq(nf, 6);
    uint32_t u = (uint32_t)L[p + 6 + 2 * nf] | (uint32_t)L[p + 7 + 2 * nf] << 8 |
                 (uint32_t)L[p + 8 + 2 * nf] << 16 | (uint32_t)L[p + 9 + 2 * nf] << 24;
    float x0;
    memcpy(&x0, &u, 4);
    ck_assert(f.xyz[0] == (double)x0);
    free(L);
    /* the same cube in doubles: the float file rounds each value once */
    int red = jf_attr_find(&f.attrs, "colorRed"), red_d = jf_attr_find(&d.attrs, "colorRed");
    int sc = jf_attr_find(&f.attrs, "scan");
    ck_assert_int_ge(red, 0);
    ck_assert_int_ge(sc, 0);
    ck_assert_int_eq(f.attrs.attr[red].type, JF_ATTR_U8); /* Integer [0, 255] */
    for (size_t i = 0; i < f.n; i++) {
        for (int a = 0; a < 3; a++)
            ck_assert_double_eq_tol(f.xyz[3 * i + a], d.xyz[3 * i + a], 3e-8);
        ck_assert(jf_attr_get(&f.attrs, (size_t)red, i) == jf_attr_get(&d.attrs, (size_t)red_d, i));
        ck_assert(jf_attr_get(&f.attrs, (size_t)sc, i) == 0);
    }
    jf_cloud_free(&f);
    jf_cloud_free(&d);
    free(x);
}
END_TEST

/* ScaledInteger coordinates (32 bits, scale 1e-6) and (10 bits, 1e-3):
 * bounds equal the files' cartesianBounds. */
START_TEST(scaled_integers_match_their_bounds)
{
    const char *files[2] = {DATA "bunnyInt32.e57", DATA "ColourRepresentation.e57"};
    for (int fi = 0; fi < 2; fi++) {
        size_t ln;
        char *x = logical(files[fi], &ln);
        jf_cloud c = read_ok(files[fi]);
        ck_assert_uint_eq(c.n, (size_t)after(strstr(x, "<points"), "recordCount=\""));
        double lo[3], hi[3];
        bounds(&c, lo, hi);
        const char *mn[3] = {"<xMinimum type=\"Float\">", "<yMinimum type=\"Float\">",
                             "<zMinimum type=\"Float\">"};
        const char *mx[3] = {"<xMaximum type=\"Float\">", "<yMaximum type=\"Float\">",
                             "<zMaximum type=\"Float\">"};
        for (int a = 0; a < 3; a++) {
            ck_assert_double_eq_tol(lo[a], after(x, mn[a]), 1e-9);
            ck_assert_double_eq_tol(hi[a], after(x, mx[a]), 1e-9);
        }
        if (fi == 1) { /* 1-bit Integer returnIndex, 16-bit las:pointSourceId */
            int ri = jf_attr_find(&c.attrs, "returnIndex"), ps = jf_attr_find(&c.attrs, "las:pointSourceId");
            ck_assert_int_ge(ri, 0);
            ck_assert_int_ge(ps, 0);
            ck_assert_int_eq(c.attrs.attr[ps].type, JF_ATTR_U16);
            for (size_t i = 0; i < c.n; i++) {
                double r = jf_attr_get(&c.attrs, (size_t)ri, i);
                ck_assert(r == 0 || r == 1);
                /* raw integers times 0.001 */
                for (int a = 0; a < 3; a++)
                    ck_assert_double_eq_tol(c.xyz[3 * i + a] * 1000, nearbyint(c.xyz[3 * i + a] * 1000), 1e-9);
            }
        }
        jf_cloud_free(&c);
        free(x);
    }
}
END_TEST

static void refused_file(const char *path, const char *reason)
{
    jf_cloud c;
    memset(&c, 0x5a, sizeof c);
    jf_error e = {{0}};
    jf_status st = jf_cloud_read(path, NULL, &c, &e);
    ck_assert_msg(st != JF_OK, "%s read", path);
    char tag[600];
    snprintf(tag, sizeof tag, "%s: ", path);
    ck_assert_msg(!strncmp(e.msg, tag, strlen(tag)) && strstr(e.msg, reason),
                  "want '%s...%s', got '%s'", tag, reason, e.msg);
    ck_assert(!strchr(e.msg, '\n'));
    ck_assert_ptr_null(c.xyz);
    ck_assert_ptr_null(c.scan);
    ck_assert_ptr_null(c.scanner);
    ck_assert_ptr_null(c.attrs.rec);
}

START_TEST(their_bad_files)
{
    refused_file(DATA "bad-crc.e57", "page 0 (bytes 0-1023): checksum mismatch");
    refused_file(DATA "ZeroPoints.e57", "no points");
    refused_file(DATA "empty.e57", "no scan in /data3D");
    refused_file(DATA "测试点云.e57", "no scan in /data3D"); /* the name kept whole */
    refused_file(DATA "InvalidCVHeader.e57", "not a CompressedVector binary section");
}
END_TEST

/* ---- two scans written here ------------------------------------------ */

#define NA 24 /* azimuth steps  */
#define NE 12 /* elevation steps */
#define NS (NA * NE)
static const double SC[3] = {0.3, -0.2, 0.5}, SR = 1.0; /* the sphere */
/* poses: translations (the scanners, outside the sphere), quaternions */
static const double ST[2][3] = {{3.0, 0.5, 1.0}, {-1.5, -2.5, -0.5}};
static const double SQ[2][4] = {{0.9, 0.1, -0.3, 0.2}, {0.3, -0.5, 0.7, 0.4}};

static void quat_R(const double q0[4], double R[3][3])
{
    double n = sqrt(q0[0] * q0[0] + q0[1] * q0[1] + q0[2] * q0[2] + q0[3] * q0[3]);
    double w = q0[0] / n, x = q0[1] / n, y = q0[2] / n, z = q0[3] / n;
    double M[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                      {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                      {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    memcpy(R, M, sizeof M);
}

/* World point k of scan s: the cap of the sphere facing its scanner. */
static void sphere_point(int s, int k, double p[3])
{
    double d[3], l = 0, e1[3], e2[3];
    for (int a = 0; a < 3; a++) d[a] = ST[s][a] - SC[a], l += d[a] * d[a];
    for (int a = 0; a < 3; a++) d[a] /= sqrt(l);
    double z[3] = {0, 0, 1}, m;
    e1[0] = d[1] * z[2] - d[2] * z[1], e1[1] = d[2] * z[0] - d[0] * z[2], e1[2] = d[0] * z[1] - d[1] * z[0];
    m = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int a = 0; a < 3; a++) e1[a] /= m;
    e2[0] = d[1] * e1[2] - d[2] * e1[1], e2[1] = d[2] * e1[0] - d[0] * e1[2], e2[2] = d[0] * e1[1] - d[1] * e1[0];
    double th = (k / NA + 1) * (55.0 / NE) * M_PI / 180, ph = (k % NA) * 2 * M_PI / NA;
    for (int a = 0; a < 3; a++)
        p[a] = SC[a] + SR * (cos(th) * d[a] + sin(th) * (cos(ph) * e1[a] + sin(ph) * e2[a]));
}

static int invalid(int s, int k) { return k % 37 == 5 + s; }

/* The two-scan file: scan 0 Cartesian single floats with intensity and
 * colour; scan 1 spherical, range a 23-bit ScaledInteger (1e-6 m) and
 * angles doubles, with rowIndex.  *lo..: the local values written. */
static unsigned char *two_scans(size_t *len, void (*edit)(char *, size_t))
{
    static double v[2][6][NS];
    for (int s = 0; s < 2; s++) {
        double R[3][3];
        quat_R(SQ[s], R);
        for (int k = 0; k < NS; k++) {
            double p[3], q[3];
            sphere_point(s, k, p);
            for (int j = 0; j < 3; j++) /* local = R^T (p - t) */
                q[j] = R[0][j] * (p[0] - ST[s][0]) + R[1][j] * (p[1] - ST[s][1]) + R[2][j] * (p[2] - ST[s][2]);
            if (s == 0) {
                for (int j = 0; j < 3; j++) v[0][j][k] = q[j];
                v[0][4][k] = k % 256;      /* colorRed */
            } else {
                double r = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                v[1][0][k] = nearbyint(r * 1e6); /* raw range */
                v[1][1][k] = atan2(q[1], q[0]);
                v[1][2][k] = asin(q[2] / r);
                v[1][4][k] = k / NA;       /* rowIndex */
            }
            v[s][3][k] = invalid(s, k) ? 2 : 0;
            v[s][5][k] = 0.25 * (k % 5); /* intensity */
        }
    }
    static const ew_field f0[6] = {
        {"cartesianX", EW_FLOAT, 0, 0, 0, v[0][0], 0}, {"cartesianY", EW_FLOAT, 0, 0, 0, v[0][1], 0},
        {"cartesianZ", EW_FLOAT, 0, 0, 0, v[0][2], 0}, {"cartesianInvalidState", EW_INT, 0, 2, 0, v[0][3], 0},
        {"colorRed", EW_INT, 0, 255, 0, v[0][4], 0},   {"intensity", EW_FLOAT, 0, 0, 0, v[0][5], 0}};
    static const ew_field f1[6] = {
        {"sphericalRange", EW_SCALED, 0, 8388607, 1e-6, v[1][0], 0},
        {"sphericalAzimuth", EW_DOUBLE, 0, 0, 0, v[1][1], 0},
        {"sphericalElevation", EW_DOUBLE, 0, 0, 0, v[1][2], 0},
        {"sphericalInvalidState", EW_INT, 0, 2, 0, v[1][3], 0},
        {"rowIndex", EW_INT, 0, NE - 1, 0, v[1][4], 0},
        {"intensity", EW_DOUBLE, 0, 0, 0, v[1][5], 0}};
    ew_scan sc[2] = {{{0}, {0}, NS, f0, 6}, {{0}, {0}, NS, f1, 6}};
    for (int s = 0; s < 2; s++) {
        memcpy(sc[s].q, SQ[s], sizeof SQ[s]);
        memcpy(sc[s].t, ST[s], sizeof ST[s]);
    }
    /* 101-byte pieces: values straddle packets and pages */
    return ew_make(sc, 2, 101, edit, len);
}

START_TEST(two_scans_one_frame)
{
    size_t len;
    unsigned char *b = two_scans(&len, NULL);
    char path[256];
    snprintf(path, sizeof path, "%s/two.e57", tmpdir);
    ck_assert_int_eq(ew_save(path, b, len), 0);
    free(b);
    jf_cloud c = read_ok(path);
    ck_assert_uint_eq(c.n, 2 * NS);
    ck_assert_uint_eq(c.nscans, 2);
    int in = jf_attr_find(&c.attrs, "intensity"), red = jf_attr_find(&c.attrs, "colorRed"),
        row = jf_attr_find(&c.attrs, "rowIndex"), sc = jf_attr_find(&c.attrs, "scan");
    ck_assert(in >= 0 && red >= 0 && row >= 0 && sc >= 0);
    ck_assert_int_eq(jf_attr_find(&c.attrs, "cartesianInvalidState"), -1);
    ck_assert_int_eq(c.attrs.attr[in].type, JF_ATTR_F64); /* single in one scan, double in the other */
    size_t nan_rows = 0;
    for (int s = 0; s < 2; s++) {
        for (int a = 0; a < 3; a++) ck_assert(c.scanner[3 * s + a] == ST[s][a]);
        for (int k = 0; k < NS; k++) {
            size_t i = (size_t)s * NS + (size_t)k;
            const double *x = c.xyz + 3 * i;
            ck_assert_uint_eq(c.scan[i], (uint32_t)s);
            ck_assert(jf_attr_get(&c.attrs, (size_t)sc, i) == s);
            ck_assert(jf_attr_get(&c.attrs, (size_t)in, i) == 0.25 * (k % 5));
            if (s == 0) {
                ck_assert(jf_attr_get(&c.attrs, (size_t)red, i) == k % 256);
                ck_assert(jf_attr_get(&c.attrs, (size_t)row, i) == 0); /* absent integer: 0 */
            } else {
                ck_assert(jf_attr_get(&c.attrs, (size_t)red, i) == 0);
                ck_assert(jf_attr_get(&c.attrs, (size_t)row, i) == k / NA);
            }
            if (invalid(s, k)) {
                ck_assert(isnan(x[0]) && isnan(x[1]) && isnan(x[2]));
                nan_rows++;
                continue;
            }
            double p[3];
            sphere_point(s, k, p);
            /* floats: 2^-24 relative of local values < 4; range: 5e-7 */
            for (int a = 0; a < 3; a++)
                ck_assert_msg(fabs(x[a] - p[a]) < (s ? 1e-6 : 1e-6), "scan %d point %d axis %d: %.9g vs %.9g",
                              s, k, a, x[a], p[a]);
        }
    }
    ck_assert_uint_eq(nan_rows, 2 * ((NS - 6) / 37 + 1));

    /* the default orientation for scans: each normal faces its scanner */
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    jf_result *res = calloc(c.n, sizeof *res);
    jf_error e = {{0}};
    ck_assert_msg(jf_estimate(&c, &o, res, &e) == JF_OK, "%s", e.msg);
    size_t good = 0, fitted = 0;
    for (size_t i = 0; i < c.n; i++) {
        const double *x = c.xyz + 3 * i, *sp = c.scanner + 3 * c.scan[i];
        if (isnan(x[0])) {
            ck_assert(res[i].status & JF_PT_NONFINITE);
            continue;
        }
        fitted++;
        double dt = 0, out = 0;
        for (int k = 0; k < 3; k++) {
            dt += res[i].normal[k] * (sp[k] - x[k]);
            out += res[i].normal[k] * (x[k] - SC[k]); /* outward on this sphere */
        }
        good += dt > 0 && out > 0;
    }
    ck_assert_msg(good * 100 >= fitted * 99, "%zu of %zu normals face their scanner", good, fitted);
    free(res);
    jf_cloud_free(&c);
}
END_TEST

/* ---- damaged and lying files ----------------------------------------- */

static const char *edit_from, *edit_to;
static int edit_all; /* every occurrence, else the first */
static void edit_xml(char *x, size_t cap)
{
    char *p = strstr(x, edit_from);
    ck_assert_ptr_nonnull(p);
    do {
        size_t a = strlen(edit_from), b = strlen(edit_to), rest = strlen(p + a);
        ck_assert(strlen(x) - a + b < cap);
        memmove(p + b, p + a, rest + 1);
        memcpy(p, edit_to, b);
        p = strstr(p + b, edit_from);
    } while (edit_all && p);
}

static void lie(const char *from, const char *to, const char *reason)
{
    edit_from = from, edit_to = to;
    size_t len;
    unsigned char *b = two_scans(&len, edit_xml);
    char path[256];
    snprintf(path, sizeof path, "%s/lie.e57", tmpdir);
    ck_assert_int_eq(ew_save(path, b, len), 0);
    free(b);
    refused_file(path, reason);
}

START_TEST(lies_refused)
{
    char rc[64];
    snprintf(rc, sizeof rc, "recordCount=\"%d\"", NS);
    lie(rc, "recordCount=\"100000\"", "recordCount 100000 needs 138 bits a record, more than its binary section");
    lie(rc, "recordCount=\"300\"", "recordCount is 300 but the binary section holds 288 values of field cartesianX");
    lie(rc, "recordCount=\"99999999999\"", "more than the file's");
    lie("maximum=\"8388607\"", "maximum=\"36893488147419103232\"", "not a 64-bit integer");
    lie("<colorRed type=\"Integer\"", "<colorRed type=\"Bogus\"", "type 'Bogus' cannot be a point field");
    lie("</e57Root>", "</e57Roo>", "XML section, line");
    lie("<x type=\"Float\">3</x>", "<x type=\"Float\">three</x>", "pose translation x");
    lie("maximum=\"255\"", "maximum=\"200\"", "record 201: field colorRed is outside its declared range");
    lie("<cartesianX type=\"Float\" precision=\"single\"/>", "", "neither cartesianX/Y/Z");
    size_t len;
    unsigned char *b = two_scans(&len, NULL);
    char path[256];
    snprintf(path, sizeof path, "%s/ok.e57", tmpdir);
    ck_assert_int_eq(ew_save(path, b, len), 0);

    /* a page's checksum: flip a byte of page 2 */
    unsigned char *m = malloc(len);
    memcpy(m, b, len);
    m[2 * 1024 + 77] ^= 0x10;
    snprintf(path, sizeof path, "%s/crc.e57", tmpdir);
    ck_assert_int_eq(ew_save(path, m, len), 0);
    refused_file(path, "page 2 (bytes 2048-3071): checksum mismatch");
    /* truncated: a page short, half a page short, the header cut */
    snprintf(path, sizeof path, "%s/cut.e57", tmpdir);
    ck_assert_int_eq(ew_save(path, b, len - 1024), 0);
    refused_file(path, "truncated");
    ck_assert_int_eq(ew_save(path, b, len - 512), 0);
    refused_file(path, "truncated");
    ck_assert_int_eq(ew_save(path, b, 30), 0);
    refused_file(path, "truncated");
    free(m);
    free(b);
}
END_TEST

START_TEST(empty_scans_refused)
{
    char rc[64];
    snprintf(rc, sizeof rc, "recordCount=\"%d\"", NS);
    edit_all = 1;
    lie(rc, "recordCount=\"0\"", "no points: the 2 scans in /data3D are all empty");
    edit_all = 0;
}
END_TEST

/* The command: exit status 1, the one line, no output file. */
START_TEST(command_exit_status)
{
    char cmd[1024], out[300];
    snprintf(out, sizeof out, "%s/out.ply", tmpdir);
    snprintf(cmd, sizeof cmd, "'%s/jetfit' estimate '%s' -o '%s' 2>'%s/err.txt'", JF_BUILD_DIR,
             DATA "bad-crc.e57", out, tmpdir);
    int rc = system(cmd);
    ck_assert(WIFEXITED(rc) && WEXITSTATUS(rc) == 1);
    struct stat sb;
    ck_assert_int_ne(stat(out, &sb), 0);
    char ep[300];
    snprintf(ep, sizeof ep, "%s/err.txt", tmpdir);
    size_t n;
    unsigned char *t = jf_test_slurp(ep, &n);
    ck_assert_msg(strstr((char *)t, "jetfit: " DATA "bad-crc.e57: page 0") == (char *)t, "%s", t);
    ck_assert(n > 0 && t[n - 1] == '\n' && !memchr(t, '\n', n - 1));
    free(t);
}
END_TEST

/* The command on the two-scan file, no --orient given: x y z, the
 * attributes, then the normals, each facing the scanner of its row's scan. */
START_TEST(command_default_orientation)
{
    size_t len;
    unsigned char *b = two_scans(&len, NULL);
    char in[300], out[300], cmd[1024];
    snprintf(in, sizeof in, "%s/two.e57", tmpdir);
    snprintf(out, sizeof out, "%s/out.csv", tmpdir);
    ck_assert_int_eq(ew_save(in, b, len), 0);
    free(b);
    snprintf(cmd, sizeof cmd, "'%s/jetfit' estimate '%s' -o '%s' --quiet", JF_BUILD_DIR, in, out);
    ck_assert_int_eq(system(cmd), 0);
    FILE *f = fopen(out, "r");
    ck_assert_ptr_nonnull(f);
    char line[4096];
    ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
    ck_assert_msg(!strncmp(line, "x,y,z,colorRed,intensity,rowIndex,scan,nx,ny,nz,", 48), "%s", line);
    size_t good = 0, fitted = 0, rows = 0;
    double v[10];
    while (fgets(line, sizeof line, f)) {
        char *p = line;
        for (int k = 0; k < 10; k++) {
            v[k] = strtod(p, &p);
            if (*p == ',') p++;
        }
        rows++;
        if (isnan(v[0])) continue;
        int s = (int)v[6];
        ck_assert(s == 0 || s == 1);
        double dt = 0;
        for (int k = 0; k < 3; k++) dt += v[7 + k] * (ST[s][k] - v[k]);
        fitted++;
        good += dt > 0;
    }
    fclose(f);
    ck_assert_uint_eq(rows, 2 * NS);
    ck_assert_msg(good * 100 >= fitted * 99, "%zu of %zu", good, fitted);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("io_e57");
    TCase *tc = tcase_create("core");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, cubes_float_and_double);
    tcase_add_test(tc, scaled_integers_match_their_bounds);
    tcase_add_test(tc, their_bad_files);
    tcase_add_test(tc, two_scans_one_frame);
    tcase_add_test(tc, lies_refused);
    tcase_add_test(tc, empty_scans_refused);
    tcase_add_test(tc, command_exit_status);
    tcase_add_test(tc, command_default_orientation);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return jf_test_run(suite());
}
