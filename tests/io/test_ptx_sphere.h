/* test_ptx_sphere.h -- a PTX file of two scans of one sphere from opposite
 * sides, written by the tests (io and cli suites).  Each scan stores its
 * points in its own frame: p_local = (p_reg - t) R^T, so the reader's
 * row-vector transform p_reg = p_local R + t brings them back; the scanner
 * position line is t (the scanner at its own origin, as Leica exports
 * write it).  Cells (row 3, col 5) and (row 7, every col) are "0 0 0"
 * (no return).  Scan 0 carries colour (7 values a line), scan 1 not. */
#ifndef JF_TEST_PTX_SPHERE_H
#define JF_TEST_PTX_SPHERE_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define PTX_COLS 40
#define PTX_ROWS 16
#define PTX_N (2 * PTX_COLS * PTX_ROWS)
static const double ptx_C[3] = {1.0, 2.0, 3.0}, ptx_R = 1.5;
/* scanner positions (registered frame), opposite sides of the sphere */
static const double ptx_S[2][3] = {{1.5, 0.5, 8.0}, {0.4, 3.1, -2.5}};

static inline int ptx_noreturn(int row, int col) { return (row == 3 && col == 5) || row == 7; }

/* Rotation of scan s (rows of R): Rz(a) Rx(b), a, b per scan. */
static inline void ptx_rot(int s, double R[3][3])
{
    double a = s ? -1.1 : 0.52, b = s ? 2.3 : 0.7;
    double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b);
    double Rz[3][3] = {{ca, -sa, 0}, {sa, ca, 0}, {0, 0, 1}};
    double Rx[3][3] = {{1, 0, 0}, {0, cb, -sb}, {0, sb, cb}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            R[i][j] = 0;
            for (int k = 0; k < 3; k++) R[i][j] += Rz[i][k] * Rx[k][j];
        }
}

/* Registered point of scan s, cell (row, col): the cap of the sphere
 * facing the scanner (up to 60 degrees, all seen by it from its direction). */
static inline void ptx_point(int s, int row, int col, double p[3])
{
    double d[3], l = 0, e1[3], e2[3];
    for (int k = 0; k < 3; k++) d[k] = ptx_S[s][k] - ptx_C[k], l += d[k] * d[k];
    for (int k = 0; k < 3; k++) d[k] /= sqrt(l);
    /* e1 = unit(d x z), e2 = d x e1 */
    double z[3] = {0, 0, 1}, m;
    e1[0] = d[1] * z[2] - d[2] * z[1], e1[1] = d[2] * z[0] - d[0] * z[2], e1[2] = d[0] * z[1] - d[1] * z[0];
    m = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int k = 0; k < 3; k++) e1[k] /= m;
    e2[0] = d[1] * e1[2] - d[2] * e1[1], e2[1] = d[2] * e1[0] - d[0] * e1[2], e2[2] = d[0] * e1[1] - d[1] * e1[0];
    double th = (row + 1) * (60.0 / PTX_ROWS) * M_PI / 180, ph = col * 2 * M_PI / PTX_COLS;
    for (int k = 0; k < 3; k++)
        p[k] = ptx_C[k] + ptx_R * (cos(th) * d[k] + sin(th) * (cos(ph) * e1[k] + sin(ph) * e2[k]));
}

/* Writes the two scans to path. */
static inline void ptx_write(const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) exit(2);
    for (int s = 0; s < 2; s++) {
        double R[3][3];
        const double *t = ptx_S[s];
        ptx_rot(s, R);
        fprintf(f, "%d\n%d\n", PTX_COLS, PTX_ROWS);
        fprintf(f, "%.17g %.17g %.17g\n", t[0], t[1], t[2]);
        for (int i = 0; i < 3; i++) fprintf(f, "%.17g %.17g %.17g\n", R[i][0], R[i][1], R[i][2]);
        for (int i = 0; i < 3; i++) fprintf(f, "%.17g %.17g %.17g 0\n", R[i][0], R[i][1], R[i][2]);
        fprintf(f, "%.17g %.17g %.17g 1\n", t[0], t[1], t[2]);
        /* PTX lists a scan column by column */
        for (int col = 0; col < PTX_COLS; col++)
            for (int row = 0; row < PTX_ROWS; row++) {
                double p[3], q[3];
                ptx_point(s, row, col, p);
                for (int j = 0; j < 3; j++) /* q = (p - t) R^T */
                    q[j] = (p[0] - t[0]) * R[j][0] + (p[1] - t[1]) * R[j][1] + (p[2] - t[2]) * R[j][2];
                if (ptx_noreturn(row, col))
                    fprintf(f, "0 0 0 0.5%s\n", s ? "" : " 0 0 0");
                else
                    fprintf(f, "%.17g %.17g %.17g 0.25%s\n", q[0], q[1], q[2], s ? "" : " 10 20 30");
            }
    }
    fclose(f);
}
#endif
