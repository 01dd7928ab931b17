/*
 * io_lemire.c -- m 10^q correctly rounded to a double by the Eisel-Lemire
 * algorithm (D. Lemire, "Number parsing at a gigabyte per second",
 * Software: Practice and Experience 51(8), 2021, §5-6; the fast path of
 * fast_float, Rust's core and Go's strconv), for jf_parse_double.
 *
 * design: w = m shifted so its top bit is set; the product of w and a
 * 128-bit truncation of 5^q (normalised, table below) is exact or a
 * close underestimate; its top 55 bits give the 53-bit significand plus
 * a rounding bit, and the power of two comes from q log2(10).  When the
 * truncation could change the rounding (the product's 9 bits below the
 * significand are all ones after the second 64-bit product, outside
 * q in [-27, 55]) the answer is "don't know", as are subnormal results
 * and q outside the table: the caller then takes its exact 128-bit path
 * or strtod.  Exactly halfway cases (only for q in [-4, 23], where 5^q
 * is exact) round to even.  Replaces, for 17-digit %.17g numbers, an
 * exact 128-bit division (__udivmodti4: ~1% of a text run at 10^6
 * points, ~3x the time of the multiplications here).
 */
#include "io_internal.h"

#include <string.h>

/* 5^q for q in [JF_POW5_MIN, JF_POW5_MAX] as 128 bits (hi, lo): for q >=
 * 0 the top 128 bits of 5^q (exact up to q = 55), for q < 0 floor(2^b /
 * 5^-q) + 1 scaled to 128 bits -- the table of fast_float's
 * table_generation.py, cut to |q| <= 64 (coordinates' exponents; the
 * rest goes to strtod). */
#define JF_POW5_MIN (-64)
#define JF_POW5_MAX 64
static const uint64_t pow5_128[JF_POW5_MAX - JF_POW5_MIN + 1][2] = {
    {0xa87fea27a539e9a5ULL, 0x3f2398d747b36224ULL}, /* 5^-64 */
    {0xd29fe4b18e88640eULL, 0x8eec7f0d19a03aadULL}, /* 5^-63 */
    {0x83a3eeeef9153e89ULL, 0x1953cf68300424acULL}, /* 5^-62 */
    {0xa48ceaaab75a8e2bULL, 0x5fa8c3423c052dd7ULL}, /* 5^-61 */
    {0xcdb02555653131b6ULL, 0x3792f412cb06794dULL}, /* 5^-60 */
    {0x808e17555f3ebf11ULL, 0xe2bbd88bbee40bd0ULL}, /* 5^-59 */
    {0xa0b19d2ab70e6ed6ULL, 0x5b6aceaeae9d0ec4ULL}, /* 5^-58 */
    {0xc8de047564d20a8bULL, 0xf245825a5a445275ULL}, /* 5^-57 */
    {0xfb158592be068d2eULL, 0xeed6e2f0f0d56712ULL}, /* 5^-56 */
    {0x9ced737bb6c4183dULL, 0x55464dd69685606bULL}, /* 5^-55 */
    {0xc428d05aa4751e4cULL, 0xaa97e14c3c26b886ULL}, /* 5^-54 */
    {0xf53304714d9265dfULL, 0xd53dd99f4b3066a8ULL}, /* 5^-53 */
    {0x993fe2c6d07b7fabULL, 0xe546a8038efe4029ULL}, /* 5^-52 */
    {0xbf8fdb78849a5f96ULL, 0xde98520472bdd033ULL}, /* 5^-51 */
    {0xef73d256a5c0f77cULL, 0x963e66858f6d4440ULL}, /* 5^-50 */
    {0x95a8637627989aadULL, 0xdde7001379a44aa8ULL}, /* 5^-49 */
    {0xbb127c53b17ec159ULL, 0x5560c018580d5d52ULL}, /* 5^-48 */
    {0xe9d71b689dde71afULL, 0xaab8f01e6e10b4a6ULL}, /* 5^-47 */
    {0x9226712162ab070dULL, 0xcab3961304ca70e8ULL}, /* 5^-46 */
    {0xb6b00d69bb55c8d1ULL, 0x3d607b97c5fd0d22ULL}, /* 5^-45 */
    {0xe45c10c42a2b3b05ULL, 0x8cb89a7db77c506aULL}, /* 5^-44 */
    {0x8eb98a7a9a5b04e3ULL, 0x77f3608e92adb242ULL}, /* 5^-43 */
    {0xb267ed1940f1c61cULL, 0x55f038b237591ed3ULL}, /* 5^-42 */
    {0xdf01e85f912e37a3ULL, 0x6b6c46dec52f6688ULL}, /* 5^-41 */
    {0x8b61313bbabce2c6ULL, 0x2323ac4b3b3da015ULL}, /* 5^-40 */
    {0xae397d8aa96c1b77ULL, 0xabec975e0a0d081aULL}, /* 5^-39 */
    {0xd9c7dced53c72255ULL, 0x96e7bd358c904a21ULL}, /* 5^-38 */
    {0x881cea14545c7575ULL, 0x7e50d64177da2e54ULL}, /* 5^-37 */
    {0xaa242499697392d2ULL, 0xdde50bd1d5d0b9e9ULL}, /* 5^-36 */
    {0xd4ad2dbfc3d07787ULL, 0x955e4ec64b44e864ULL}, /* 5^-35 */
    {0x84ec3c97da624ab4ULL, 0xbd5af13bef0b113eULL}, /* 5^-34 */
    {0xa6274bbdd0fadd61ULL, 0xecb1ad8aeacdd58eULL}, /* 5^-33 */
    {0xcfb11ead453994baULL, 0x67de18eda5814af2ULL}, /* 5^-32 */
    {0x81ceb32c4b43fcf4ULL, 0x80eacf948770ced7ULL}, /* 5^-31 */
    {0xa2425ff75e14fc31ULL, 0xa1258379a94d028dULL}, /* 5^-30 */
    {0xcad2f7f5359a3b3eULL, 0x096ee45813a04330ULL}, /* 5^-29 */
    {0xfd87b5f28300ca0dULL, 0x8bca9d6e188853fcULL}, /* 5^-28 */
    {0x9e74d1b791e07e48ULL, 0x775ea264cf55347eULL}, /* 5^-27 */
    {0xc612062576589ddaULL, 0x95364afe032a819eULL}, /* 5^-26 */
    {0xf79687aed3eec551ULL, 0x3a83ddbd83f52205ULL}, /* 5^-25 */
    {0x9abe14cd44753b52ULL, 0xc4926a9672793543ULL}, /* 5^-24 */
    {0xc16d9a0095928a27ULL, 0x75b7053c0f178294ULL}, /* 5^-23 */
    {0xf1c90080baf72cb1ULL, 0x5324c68b12dd6339ULL}, /* 5^-22 */
    {0x971da05074da7beeULL, 0xd3f6fc16ebca5e04ULL}, /* 5^-21 */
    {0xbce5086492111aeaULL, 0x88f4bb1ca6bcf585ULL}, /* 5^-20 */
    {0xec1e4a7db69561a5ULL, 0x2b31e9e3d06c32e6ULL}, /* 5^-19 */
    {0x9392ee8e921d5d07ULL, 0x3aff322e62439fd0ULL}, /* 5^-18 */
    {0xb877aa3236a4b449ULL, 0x09befeb9fad487c3ULL}, /* 5^-17 */
    {0xe69594bec44de15bULL, 0x4c2ebe687989a9b4ULL}, /* 5^-16 */
    {0x901d7cf73ab0acd9ULL, 0x0f9d37014bf60a11ULL}, /* 5^-15 */
    {0xb424dc35095cd80fULL, 0x538484c19ef38c95ULL}, /* 5^-14 */
    {0xe12e13424bb40e13ULL, 0x2865a5f206b06fbaULL}, /* 5^-13 */
    {0x8cbccc096f5088cbULL, 0xf93f87b7442e45d4ULL}, /* 5^-12 */
    {0xafebff0bcb24aafeULL, 0xf78f69a51539d749ULL}, /* 5^-11 */
    {0xdbe6fecebdedd5beULL, 0xb573440e5a884d1cULL}, /* 5^-10 */
    {0x89705f4136b4a597ULL, 0x31680a88f8953031ULL}, /* 5^-9 */
    {0xabcc77118461cefcULL, 0xfdc20d2b36ba7c3eULL}, /* 5^-8 */
    {0xd6bf94d5e57a42bcULL, 0x3d32907604691b4dULL}, /* 5^-7 */
    {0x8637bd05af6c69b5ULL, 0xa63f9a49c2c1b110ULL}, /* 5^-6 */
    {0xa7c5ac471b478423ULL, 0x0fcf80dc33721d54ULL}, /* 5^-5 */
    {0xd1b71758e219652bULL, 0xd3c36113404ea4a9ULL}, /* 5^-4 */
    {0x83126e978d4fdf3bULL, 0x645a1cac083126eaULL}, /* 5^-3 */
    {0xa3d70a3d70a3d70aULL, 0x3d70a3d70a3d70a4ULL}, /* 5^-2 */
    {0xccccccccccccccccULL, 0xcccccccccccccccdULL}, /* 5^-1 */
    {0x8000000000000000ULL, 0x0000000000000000ULL}, /* 5^0 */
    {0xa000000000000000ULL, 0x0000000000000000ULL}, /* 5^1 */
    {0xc800000000000000ULL, 0x0000000000000000ULL}, /* 5^2 */
    {0xfa00000000000000ULL, 0x0000000000000000ULL}, /* 5^3 */
    {0x9c40000000000000ULL, 0x0000000000000000ULL}, /* 5^4 */
    {0xc350000000000000ULL, 0x0000000000000000ULL}, /* 5^5 */
    {0xf424000000000000ULL, 0x0000000000000000ULL}, /* 5^6 */
    {0x9896800000000000ULL, 0x0000000000000000ULL}, /* 5^7 */
    {0xbebc200000000000ULL, 0x0000000000000000ULL}, /* 5^8 */
    {0xee6b280000000000ULL, 0x0000000000000000ULL}, /* 5^9 */
    {0x9502f90000000000ULL, 0x0000000000000000ULL}, /* 5^10 */
    {0xba43b74000000000ULL, 0x0000000000000000ULL}, /* 5^11 */
    {0xe8d4a51000000000ULL, 0x0000000000000000ULL}, /* 5^12 */
    {0x9184e72a00000000ULL, 0x0000000000000000ULL}, /* 5^13 */
    {0xb5e620f480000000ULL, 0x0000000000000000ULL}, /* 5^14 */
    {0xe35fa931a0000000ULL, 0x0000000000000000ULL}, /* 5^15 */
    {0x8e1bc9bf04000000ULL, 0x0000000000000000ULL}, /* 5^16 */
    {0xb1a2bc2ec5000000ULL, 0x0000000000000000ULL}, /* 5^17 */
    {0xde0b6b3a76400000ULL, 0x0000000000000000ULL}, /* 5^18 */
    {0x8ac7230489e80000ULL, 0x0000000000000000ULL}, /* 5^19 */
    {0xad78ebc5ac620000ULL, 0x0000000000000000ULL}, /* 5^20 */
    {0xd8d726b7177a8000ULL, 0x0000000000000000ULL}, /* 5^21 */
    {0x878678326eac9000ULL, 0x0000000000000000ULL}, /* 5^22 */
    {0xa968163f0a57b400ULL, 0x0000000000000000ULL}, /* 5^23 */
    {0xd3c21bcecceda100ULL, 0x0000000000000000ULL}, /* 5^24 */
    {0x84595161401484a0ULL, 0x0000000000000000ULL}, /* 5^25 */
    {0xa56fa5b99019a5c8ULL, 0x0000000000000000ULL}, /* 5^26 */
    {0xcecb8f27f4200f3aULL, 0x0000000000000000ULL}, /* 5^27 */
    {0x813f3978f8940984ULL, 0x4000000000000000ULL}, /* 5^28 */
    {0xa18f07d736b90be5ULL, 0x5000000000000000ULL}, /* 5^29 */
    {0xc9f2c9cd04674edeULL, 0xa400000000000000ULL}, /* 5^30 */
    {0xfc6f7c4045812296ULL, 0x4d00000000000000ULL}, /* 5^31 */
    {0x9dc5ada82b70b59dULL, 0xf020000000000000ULL}, /* 5^32 */
    {0xc5371912364ce305ULL, 0x6c28000000000000ULL}, /* 5^33 */
    {0xf684df56c3e01bc6ULL, 0xc732000000000000ULL}, /* 5^34 */
    {0x9a130b963a6c115cULL, 0x3c7f400000000000ULL}, /* 5^35 */
    {0xc097ce7bc90715b3ULL, 0x4b9f100000000000ULL}, /* 5^36 */
    {0xf0bdc21abb48db20ULL, 0x1e86d40000000000ULL}, /* 5^37 */
    {0x96769950b50d88f4ULL, 0x1314448000000000ULL}, /* 5^38 */
    {0xbc143fa4e250eb31ULL, 0x17d955a000000000ULL}, /* 5^39 */
    {0xeb194f8e1ae525fdULL, 0x5dcfab0800000000ULL}, /* 5^40 */
    {0x92efd1b8d0cf37beULL, 0x5aa1cae500000000ULL}, /* 5^41 */
    {0xb7abc627050305adULL, 0xf14a3d9e40000000ULL}, /* 5^42 */
    {0xe596b7b0c643c719ULL, 0x6d9ccd05d0000000ULL}, /* 5^43 */
    {0x8f7e32ce7bea5c6fULL, 0xe4820023a2000000ULL}, /* 5^44 */
    {0xb35dbf821ae4f38bULL, 0xdda2802c8a800000ULL}, /* 5^45 */
    {0xe0352f62a19e306eULL, 0xd50b2037ad200000ULL}, /* 5^46 */
    {0x8c213d9da502de45ULL, 0x4526f422cc340000ULL}, /* 5^47 */
    {0xaf298d050e4395d6ULL, 0x9670b12b7f410000ULL}, /* 5^48 */
    {0xdaf3f04651d47b4cULL, 0x3c0cdd765f114000ULL}, /* 5^49 */
    {0x88d8762bf324cd0fULL, 0xa5880a69fb6ac800ULL}, /* 5^50 */
    {0xab0e93b6efee0053ULL, 0x8eea0d047a457a00ULL}, /* 5^51 */
    {0xd5d238a4abe98068ULL, 0x72a4904598d6d880ULL}, /* 5^52 */
    {0x85a36366eb71f041ULL, 0x47a6da2b7f864750ULL}, /* 5^53 */
    {0xa70c3c40a64e6c51ULL, 0x999090b65f67d924ULL}, /* 5^54 */
    {0xd0cf4b50cfe20765ULL, 0xfff4b4e3f741cf6dULL}, /* 5^55 */
    {0x82818f1281ed449fULL, 0xbff8f10e7a8921a4ULL}, /* 5^56 */
    {0xa321f2d7226895c7ULL, 0xaff72d52192b6a0dULL}, /* 5^57 */
    {0xcbea6f8ceb02bb39ULL, 0x9bf4f8a69f764490ULL}, /* 5^58 */
    {0xfee50b7025c36a08ULL, 0x02f236d04753d5b4ULL}, /* 5^59 */
    {0x9f4f2726179a2245ULL, 0x01d762422c946590ULL}, /* 5^60 */
    {0xc722f0ef9d80aad6ULL, 0x424d3ad2b7b97ef5ULL}, /* 5^61 */
    {0xf8ebad2b84e0d58bULL, 0xd2e0898765a7deb2ULL}, /* 5^62 */
    {0x9b934c3b330c8577ULL, 0x63cc55f49f88eb2fULL}, /* 5^63 */
    {0xc2781f49ffcfa6d5ULL, 0x3cbf6b71c76b25fbULL}, /* 5^64 */
};

/* floor(q log2(10)) + 63, exact for |q| <= 4000 (217706 / 2^16). */
static int power2_of(int q) { return ((q * (152170 + 65536)) >> 16) + 63; }

int jf__lemire(uint64_t m, int q, double *out)
{
    if (m == 0 || q < JF_POW5_MIN || q > JF_POW5_MAX)
        return 0;
    const int lz = __builtin_clzll(m);
    const uint64_t w = m << lz;
    const uint64_t *p5 = pow5_128[q - JF_POW5_MIN];
    /* the top 64 bits of w 5^q, and the next 64 if the first product's
     * bits below the 55 we keep are all ones (a carry could reach them) */
    unsigned __int128 first = (unsigned __int128)w * p5[0];
    uint64_t hi = (uint64_t)(first >> 64), lo = (uint64_t)first;
    const uint64_t mask = UINT64_MAX >> 55;
    if ((hi & mask) == mask) {
        const uint64_t second_hi = (uint64_t)(((unsigned __int128)w * p5[1]) >> 64);
        lo += second_hi;
        if (second_hi > lo)
            hi++;
    }
    if (lo == UINT64_MAX && (q < -27 || q > 55))
        return 0; /* the truncation of 5^q may matter: don't know */
    const int upper = (int)(hi >> 63), shift = upper + 64 - 52 - 3;
    uint64_t mant = hi >> shift;
    int e2 = power2_of(q) + upper - lz + 1023; /* biased exponent */
    if (e2 <= 0)
        return 0; /* subnormal or zero: strtod */
    /* exactly halfway between two doubles (only where 5^q is exact and
     * nothing but zeros was shifted out): round to even, i.e. down */
    if (lo <= 1 && q >= -4 && q <= 23 && (mant & 3) == 1 && (mant << shift) == hi)
        mant &= ~(uint64_t)1;
    mant += mant & 1; /* round half up, on the 54th bit */
    mant >>= 1;
    if (mant >= (uint64_t)2 << 52) { /* carried into a new bit */
        mant = (uint64_t)1 << 52;
        e2++;
    }
    if (e2 >= 0x7FF)
        return 0; /* overflow: strtod says inf */
    const uint64_t bits = (mant & (((uint64_t)1 << 52) - 1)) | (uint64_t)e2 << 52;
    memcpy(out, &bits, sizeof bits);
    return 1;
}
