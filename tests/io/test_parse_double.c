/* test_parse_double.c -- the text readers' number parser (jf_parse_double:
 * Clinger's fast path, Eisel-Lemire, exact 128-bit integers, strtod)
 * gives strtod's correctly rounded double, bit for bit, on millions of
 * strings: %.17g of random bit patterns and of coordinates, random digit
 * strings of 1 to 19 digits with exponents -80..80 in several layouts,
 * exact ties between two doubles and their neighbours, and edge cases
 * (zeros, subnormals, the largest and smallest normals, overflow, 20+
 * digits, leading zeros).  jf__lemire alone is checked the same way, and
 * that it answers (not just declines) for nearly every normal result. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io_internal.h"
#include "jf_test.h"

static uint64_t rng_state;
static uint64_t rnd64(void) /* splitmix64, deterministic */
{
    return jf_splitmix64(&rng_state);
}

static uint64_t bits_of(double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

static size_t checked;

/* jf_parse_double(s) == strtod(s), bit for bit. */
static void same_as_strtod(const char *s)
{
    char *end;
    double ref = strtod(s, &end), v = -12345.0;
    ck_assert_msg(*end == '\0', "strtod did not take all of '%s'", s);
    ck_assert_msg(jf_parse_double(s, s + strlen(s), &v), "'%s' refused", s);
    ck_assert_msg(bits_of(v) == bits_of(ref), "'%s': %a, strtod %a", s, v, ref);
    checked++;
}

START_TEST(test_g17_random_bits)
{
    char buf[64];
    rng_state = 1;
    for (int i = 0; i < 600000; i++) {
        uint64_t u = rnd64();
        double v;
        memcpy(&v, &u, sizeof v);
        if (!isfinite(v)) continue;
        snprintf(buf, sizeof buf, "%.17g", v);
        same_as_strtod(buf);
        if (i % 4 == 0) { /* the shortest form that reads back, often 15-16 digits */
            snprintf(buf, sizeof buf, "%.15g", v);
            same_as_strtod(buf);
        }
    }
}
END_TEST

START_TEST(test_g17_coordinates)
{
    char buf[64];
    rng_state = 2;
    static const double scale[] = {1e-6, 1e-3, 0.1, 1, 10, 1000, 1e5, 6e6};
    for (int i = 0; i < 400000; i++) {
        double x = ((double)(rnd64() >> 11) * 0x1p-53 - 0.5) * scale[i % 8];
        if (i % 3 == 0) x = 0.1 * exp(2 * x + x * x); /* as the §6.1 surface */
        snprintf(buf, sizeof buf, "%.17g", x);
        same_as_strtod(buf);
    }
}
END_TEST

/* Random digit strings: n digits (1..19, leading zeros allowed), a point
 * somewhere or none, an exponent or none. */
START_TEST(test_digit_strings)
{
    char buf[128];
    rng_state = 3;
    for (int i = 0; i < 600000; i++) {
        int n = 1 + (int)(rnd64() % 19), k = 0;
        if (rnd64() % 2) buf[k++] = '-';
        int point = (int)(rnd64() % (n + 2)) - 1; /* -1: none */
        for (int j = 0; j < n; j++) {
            if (j == point) buf[k++] = '.';
            int d = (int)(rnd64() % 10);
            if (j == 0 && i % 2) d = 1 + d % 9; /* half: no leading zero */
            buf[k++] = (char)('0' + d);
        }
        if (point == n) buf[k++] = '.';
        if (rnd64() % 4) k += snprintf(buf + k, sizeof buf - (size_t)k, "e%d",
                                       (int)(rnd64() % 161) - 80);
        buf[k] = '\0';
        same_as_strtod(buf);
    }
}
END_TEST

/* Exact ties: an odd integer t in [2^53, 2^54) lies halfway between two
 * doubles, as does t 2^j; written in decimal with at most 19 digits for
 * j in [-3, 9].  Each tie, and the numbers one unit of its last digit
 * away, round as strtod does. */
START_TEST(test_ties)
{
    char buf[64];
    rng_state = 4;
    for (int i = 0; i < 300000; i++) {
        uint64_t t = ((uint64_t)1 << 53) | (rnd64() >> 11) | 1;
        int j = (int)(rnd64() % 13) - 3;
        if (j >= 0) { /* t 2^j: an integer of <= 19 digits */
            uint64_t v = t << j;
            snprintf(buf, sizeof buf, "%llu", (unsigned long long)v);
            same_as_strtod(buf);
            snprintf(buf, sizeof buf, "%llu", (unsigned long long)(v + 1));
            same_as_strtod(buf);
            snprintf(buf, sizeof buf, "%llu", (unsigned long long)(v - 1));
            same_as_strtod(buf);
        } else { /* t / 2^-j = t 5^-j / 10^-j */
            uint64_t v = t;
            for (int r = 0; r < -j; r++) v *= 5;
            for (int dlt = -1; dlt <= 1; dlt++) {
                snprintf(buf, sizeof buf, "%llue%d", (unsigned long long)(v + (uint64_t)dlt), j);
                same_as_strtod(buf);
            }
        }
    }
}
END_TEST

START_TEST(test_edge_cases)
{
    static const char *const s[] = {
        "0", "-0", "0.0", "-0.000", "0e999", "00000000000000000000000000000", ".5", "5.", "+1.5",
        "-.25e-3", "1E5", "1e+05", "1e-05", "9007199254740992", "9007199254740993",
        "9007199254740995", "9007199254740993.0000000001", "18446744073709551615",
        "18446744073709551616", "9999999999999999999", "99999999999999999999",
        "1.7976931348623157e308", "1.7976931348623158e308", "1.7976931348623159e308",
        "1e308", "1e309", "1e400", "-1e400", "2.2250738585072014e-308",
        "2.2250738585072011e-308", "2.2250738585072012e-308", "4.9406564584124654e-324",
        "2.4703282292062327e-324", "2.4703282292062328e-324", "1e-320", "1e-400",
        "0.000000000000000000000000000000000000000000000000000000000000012345678901234567",
        "123456789012345678901234567890", "0.1", "0.2", "0.3", "1e23", "8.98846567431158e307",
        "1e-64", "1e64", "1e-65", "1e65", "9.999999999999999e22", "1e22", "1e-22",
        "7.2057594037927933e16", "5e-324", "3.0517578125e-05", "0.30000000000000004",
        "1.00000000000000011102230246251565404236316680908203125",
        "1.00000000000000011102230246251565404236316680908203124",
        "1.00000000000000011102230246251565404236316680908203126", "123.456e-2",
        "000000000000000000001.5", "1.5000000000000000000000", "4503599627370496.5",
        "4503599627370497.5", "2.5e-5", "-9.8765432109876543e-31", "6.02214076e23",
    };
    for (size_t i = 0; i < sizeof s / sizeof *s; i++) same_as_strtod(s[i]);
    for (int q = -350; q <= 320; q++) { /* every power of ten, and neighbours */
        char buf[64];
        snprintf(buf, sizeof buf, "1e%d", q);
        same_as_strtod(buf);
        snprintf(buf, sizeof buf, "9999999999999999999e%d", q);
        same_as_strtod(buf);
        snprintf(buf, sizeof buf, "1000000000000000001e%d", q);
        same_as_strtod(buf);
    }
}
END_TEST

/* jf__lemire directly: right whenever it answers, and it answers for
 * almost every m 10^q with a normal result. */
START_TEST(test_lemire_direct)
{
    char buf[64];
    rng_state = 5;
    size_t answered = 0, normal = 0;
    for (int i = 0; i < 600000; i++) {
        uint64_t m = rnd64() >> (rnd64() % 64);
        if (!m) continue;
        int q = (int)(rnd64() % 141) - 70;
        snprintf(buf, sizeof buf, "%llue%d", (unsigned long long)m, q);
        double ref = strtod(buf, NULL), v;
        int ok = jf__lemire(m, q, &v);
        if (ok) ck_assert_msg(bits_of(v) == bits_of(ref), "%s: %a, strtod %a", buf, v, ref);
        if (isnormal(ref) && q >= -64 && q <= 64) {
            normal++;
            answered += ok;
        }
    }
    ck_assert_uint_gt(answered, normal - normal / 10000);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("parse_double");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_g17_random_bits);
    tcase_add_test(tc, test_g17_coordinates);
    tcase_add_test(tc, test_digit_strings);
    tcase_add_test(tc, test_ties);
    tcase_add_test(tc, test_edge_cases);
    tcase_add_test(tc, test_lemire_direct);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
