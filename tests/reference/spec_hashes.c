/* An independent C implementation of docs/spec.md sections 2, 3, 5 (Bose, CMJND),
 * 6 and 7, written from the specification text (and, for mix32 / hash_pair /
 * pixel_seed / block_seed / block_order_seed, from the documented choices in the
 * docstrings of pyoa/reference/hashes.py: Wellons' lowbias32 and hash_pair(a, b, key) =
 * lowbias32(b ^ lowbias32(a ^ key)), 0 -> key), NOT from pyoa's code.
 *
 * The block rule (section 6): dimension j of sample i, in an array of N rows and B
 * columns per block with seed p, is column j % B of the copy with seed
 * P = block_seed(p, j / B), read at row permute(permute(i, N, r), N, mix32(r)), r = block_order_seed(P, j / B, N):
 * the OA cell, the 'j' offset's cell key and the jitter's randfloat all use that row.
 *
 * The test suite compiles it at test time:
 *     cc -std=c99 -O2 -ffp-contract=off -o spec_hashes spec_hashes.c
 * and feeds it one query per line on stdin; it answers one line per query:
 *
 *     P i l p                 -> permute(i, l, p)                      (decimal)
 *     R i p                   -> bits of randfloat(i, p)               (decimal uint32)
 *     X x                     -> mix32(x)
 *     S seed pixel            -> pixel_seed(seed, pixel)
 *     B p block               -> block_seed(p, block)
 *     K P block N             -> block_order_seed(P, block, N)         (P: the block's seed)
 *     O i j s p off Jbits     -> bits of the Bose value x(i, j)        (off: 0 centered, 1 j, 2 mj, 3 cmj)
 *     C i j s t p off Jbits   -> bits of the CMJND value x(i, j)       (Jbits: float32 bits of the jitter amount)
 *
 * Float32 arithmetic: on x86-64 (SSE) and aarch64 a C float expression is
 * evaluated in float32, one correctly rounded operation at a time;
 * -ffp-contract=off forbids fused multiply-adds (docs/spec.md section 7). The
 * volatile temporaries force each intermediate to be stored as a float.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

typedef uint32_t u32;

static float from_bits(u32 u) { float f; memcpy(&f, &u, 4); return f; }
static u32 to_bits(float f) { u32 u; memcpy(&u, &f, 4); return u; }

/* docs/spec.md section 2 */
static u32 permute(u32 i, u32 l, u32 p)
{
    u32 w;
    if (p == 0) return i;
    w = l - 1;
    w |= w >> 1; w |= w >> 2; w |= w >> 4; w |= w >> 8; w |= w >> 16;
    do {
        i ^= p;            i *= 0xe170893du;
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;       i *= 0x0929eb3fu;
        i ^= p >> 23;
        i ^= (i & w) >> 1; i *= 1u | (p >> 27);
        i *= 0x6935fa69u;
        i ^= (i & w) >> 11; i *= 0x74dcb303u;
        i ^= (i & w) >> 2;  i *= 0x9e501cc3u;
        i ^= (i & w) >> 2;  i *= 0xc860a3dfu;
        i &= w;
        i ^= i >> 5;
    } while (i >= l);
    return (i + p % l) % l;
}

static float randfloat(u32 i, u32 p)
{
    volatile float f;
    if (p == 0) return 0.5f;
    i ^= p;
    i ^= i >> 17;
    i ^= i >> 10;  i *= 0xb36534e5u;
    i ^= i >> 12;
    i ^= i >> 21;  i *= 0x93fc4795u;
    i ^= 0xdf6e307fu;
    i ^= i >> 17;  i *= 1u | (p >> 18);
    f = (float)i;                        /* round to nearest even */
    f = f * from_bits(0x2f7ffffeu);      /* one float32 multiply */
    return f;
}

/* Wellons' lowbias32 */
static u32 mix32(u32 x)
{
    x ^= x >> 16; x *= 0x7feb352du;
    x ^= x >> 15; x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

static u32 hash_pair(u32 a, u32 b, u32 key)
{
    u32 h = mix32(b ^ mix32(a ^ key));
    return h ? h : key;
}

static u32 pixel_seed(u32 seed, u32 pixel) { return hash_pair(seed, pixel, 0x5bd1e995u); }
static u32 block_seed(u32 p, u32 block) { return block == 0 ? p : hash_pair(p, block, 0x1b873593u); }
/* the sample order of a block (section 6): block 0 keeps its rows (permute with seed 0 is the identity) */
static u32 block_order_seed(u32 P, u32 block, u32 N) { return block == 0 ? 0 : hash_pair(P, N, 0x94d049bbu); }

/* docs/spec.md section 6, the block rule: dimension j of sample i of an array with N
 * rows, B columns per block and seed p reads column *col of the copy with seed *P,
 * at row permute(permute(i, N, r), N, mix32(r)), r = block_order_seed(*P, block, N) (returned) */
static u32 locate(u32 p, u32 i, u32 j, u32 B, u32 N, u32 *P, u32 *col)
{
    u32 block = j / B;
    *col = j % B;
    *P = block_seed(p, block);
    u32 r = block_order_seed(*P, block, N);
    return permute(permute(i, N, r), N, mix32(r));
}

/* x * n compared with c exactly, in integers (docs/spec.md section 7): x = m 2^-e with
 * m its 24-bit significand, so x * n < c iff m n < c 2^e; m n < 2^49, and for
 * e >= 49 (x < 2^-25) the right side wins whenever c > 0, as it does when
 * c 2^e would overflow 64 bits. Returns -1, 0, 1. */
static int cmp_xn_c(float x, u32 n, u32 c)
{
    u32 b = to_bits(x), ef = b >> 23;
    unsigned long long m = ef ? ((b & 0x7fffffu) | 0x800000u) : (b & 0x7fffffu);
    int e = (ef ? 150 - (int)ef : 149);
    unsigned long long lhs = m * n;
    if (e >= 49) return c ? -1 : (lhs ? 1 : 0);
    if (e > 0 && ((unsigned long long)c >> (64 - e)) != 0) return -1;  /* c 2^e >= 2^64 > m n */
    unsigned long long rhs = (unsigned long long)c << e;
    return lhs < rhs ? -1 : lhs > rhs ? 1 : 0;
}

/* the cell clamp of docs/spec.md section 7, by definition: step one float32 at a time */
static float cell_clamp(float x, u32 c, u32 n)
{
    while (cmp_xn_c(x, n, c + 1) >= 0) x = from_bits(to_bits(x) - 1);
    while (cmp_xn_c(x, n, c) < 0) x = from_bits(to_bits(x) + 1);
    return x;
}

/* docs/spec.md sections 1, 3 and 7: x = (stratum + (sub + jitter) / M) / s, clamped into
 * its cell (the fine cell stratum M + sub, or the coarse stratum when sub is the
 * half-integer of 'centered' with even M) */
static float value(u32 stratum, float sub, u32 i, u32 P3, float J, u32 M, u32 s)
{
    volatile float r, jit, a, b, c, x;
    r = randfloat(i, P3);
    jit = r - 0.5f;
    jit = J * jit;
    jit = 0.5f + jit;
    a = sub + jit;
    b = a / (float)M;
    c = (float)stratum + b;
    x = c / (float)s;
    if ((float)(u32)sub == sub) return cell_clamp(x, stratum * M + (u32)sub, M * s);
    return cell_clamp(x, stratum, s);
}

enum { CENTERED = 0, JITTERED = 1, MJ = 2, CMJ = 3 };

/* docs/spec.md section 5, Bose; section 6 blocks of s+1 columns, N = s^2 rows:
 * the block rule gives the row to read, and from here on j is its column, p the block's seed */
static float bose(u32 i, u32 j, u32 s, u32 p, int off, float J)
{
    u32 row, a0, a1, aij, aik, k, P1, P2, P3, stratum;
    float sub;
    row = locate(p, i, j, s + 1, s * s, &p, &j);
    P1 = p * (j + 1) * 0x51633e2du;
    P2 = p * (j + 1) * 0x68bc21ebu;
    P3 = p * (j + 1) * 0x02e5be93u;
    a0 = row / s; a1 = row % s;
    if (j == 0) { aij = a0; aik = a1; }
    else if (j == 1) { aij = a1; aik = a0; }
    else {
        aij = (a0 + (j - 1) * a1) % s;
        k = (j % 2 == 1) ? j - 1 : j + 1;
        aik = (a0 + ((k - 1) % s) * a1) % s;
    }
    stratum = permute(aij, s, P1);
    switch (off) {
    case CENTERED: sub = (float)(s - 1) / 2.0f; break;
    case JITTERED: sub = (float)permute(aik, s, (aik * s + aij + 1) * P2); break;
    case MJ:       sub = (float)permute(aik, s, (aij + 1) * P2); break;
    default:       sub = (float)permute(aik, s, P2); break;
    }
    return value(stratum, sub, row, P3, J, s, s);
}

/* docs/spec.md section 5, CMJND; section 6 blocks of t columns, N = s^t rows:
 * the block rule gives the row to read, and from here on j is its column, p the block's seed */
static float cmjnd(u32 i, u32 j, u32 s, u32 t, u32 p, int off, float J)
{
    u32 row, M = 1, sj = 1, d, aij, v, P1, P2, P3, stratum, c, pw;
    float sub;
    for (d = 0; d + 1 < t; ++d) M *= s;
    row = locate(p, i, j, t, M * s, &p, &j);
    P1 = p * (j + 1) * 0x51633e2du;
    P2 = p * (j + 1) * 0x68bc21ebu;
    P3 = p * (j + 1) * 0x02e5be93u;
    for (d = 0; d < j; ++d) sj *= s;
    aij = (row / sj) % s;
    /* v: the other t-1 digits in their order, lowest remaining digit least significant */
    v = 0; pw = 1; c = row;
    for (d = 0; d < t; ++d) {
        u32 digit = c % s;
        c /= s;
        if (d == j) continue;
        v += digit * pw;
        pw *= s;
    }
    stratum = permute(aij, s, P1);
    switch (off) {
    case CENTERED: sub = (float)(M - 1) / 2.0f; break;
    case JITTERED: sub = (float)permute(v, M, (row + 1) * P2); break;
    case MJ:       sub = (float)permute(v, M, (aij + 1) * P2); break;
    default:       sub = (float)permute(v, M, P2); break;
    }
    return value(stratum, sub, row, P3, J, M, s);
}

int main(void)
{
    char line[512];
    while (fgets(line, sizeof line, stdin)) {
        unsigned long a = 0, b = 0, c = 0, d = 0, e = 0, f = 0, g = 0;
        switch (line[0]) {
        case 'P': sscanf(line + 1, "%lu %lu %lu", &a, &b, &c);
                  printf("%lu\n", (unsigned long)permute((u32)a, (u32)b, (u32)c)); break;
        case 'R': sscanf(line + 1, "%lu %lu", &a, &b);
                  printf("%lu\n", (unsigned long)to_bits(randfloat((u32)a, (u32)b))); break;
        case 'X': sscanf(line + 1, "%lu", &a);
                  printf("%lu\n", (unsigned long)mix32((u32)a)); break;
        case 'S': sscanf(line + 1, "%lu %lu", &a, &b);
                  printf("%lu\n", (unsigned long)pixel_seed((u32)a, (u32)b)); break;
        case 'B': sscanf(line + 1, "%lu %lu", &a, &b);
                  printf("%lu\n", (unsigned long)block_seed((u32)a, (u32)b)); break;
        case 'K': sscanf(line + 1, "%lu %lu %lu", &a, &b, &c);
                  printf("%lu\n", (unsigned long)block_order_seed((u32)a, (u32)b, (u32)c)); break;
        case 'O': sscanf(line + 1, "%lu %lu %lu %lu %lu %lu", &a, &b, &c, &d, &e, &f);
                  printf("%lu\n", (unsigned long)to_bits(bose((u32)a, (u32)b, (u32)c, (u32)d, (int)e,
                                                              from_bits((u32)f)))); break;
        case 'C': sscanf(line + 1, "%lu %lu %lu %lu %lu %lu %lu", &a, &b, &c, &d, &e, &f, &g);
                  printf("%lu\n", (unsigned long)to_bits(cmjnd((u32)a, (u32)b, (u32)c, (u32)d, (u32)e, (int)f,
                                                               from_bits((u32)g)))); break;
        default:  printf("?\n"); break;
        }
    }
    return 0;
}
