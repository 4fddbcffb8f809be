/* pyoa/counts.h: the catalogue's sample counts in C. Which names pyoa has,
 * which sample counts each sampler accepts and what parameters a count
 * means (s, strength t, block_dims, M), or why a count is refused, with
 * the nearest valid counts on both sides: pyoa.catalogue, pyoa.catalogue.constructions,
 * pyoa.catalogue.baselines, pyoa.catalogue.faure and the checks of pyoa.Sampler, mirrored
 * so that the C API (pyoa/sampler.h) accepts exactly the requests the Python
 * API accepts, resolves them to the same parameters and refuses the others
 * with the same message (tests/test_c_counts.py compares the two).
 *
 * Host only (PYOA_HOST_FN; nothing here exists in OpenCL C but the error
 * codes), no heap, no state: a message goes into the caller's buffer,
 * truncated like snprintf's (always terminated, never overrun).
 *
 * The functions, each documented where it is defined:
 *   pyoa_lookup, pyoa_name_error   a name or alias -> PYOA_SAMPLER_<NAME>
 *   pyoa_sampler_name              PYOA_SAMPLER_<NAME> -> its catalogue name
 *   pyoa_solve, pyoa_solve_base    (code, spp, strength, dims, resolution
 *                                  [, base]) -> pyoa_params, or an error
 *   pyoa_resolve                   everything pyoa.Sampler checks, in its
 *                                  order (name, spp, dims, offset, ...)
 *   pyoa_offset_code,              the offset style -> PYOA_OFFSET_<NAME>
 *   pyoa_sampler_offset
 *   pyoa_nearest, pyoa_nearest_spp the valid counts nearest a count
 *   pyoa_shape_args                a sampler's shape arguments (a, b, c)
 *   pyoa_needs_resolution          whether a sampler takes width x height
 *
 * Integer arithmetic only: where Python takes a float root and rounds it
 * (constructions.integer_root, _power_candidates), the exact integer root
 * is computed here, which gives the same integers for every count up to
 * 2^32 (tests/test_c_counts.py checks every rounding boundary). */
#ifndef PYOA_COUNTS_H
#define PYOA_COUNTS_H

#include "config.h"
#include "gf.h"
#include "keys.h"

/* What pyoa_solve and the others return: 0, or the kind of argument that
 * was refused. PYOA_ERROR_DIMS (dims above 2^20, or above halton's 6542
 * and sobol's 21201) and PYOA_ERROR_BASE (faure's and zfaure's base) have
 * no other code: the Python API refuses them with a ValueError of their own. */
enum {
    PYOA_OK = 0,
    PYOA_ERROR_NAME = 1,       /* no sampler of that name or alias */
    PYOA_ERROR_SPP = 2,        /* not a valid sample count of that sampler */
    PYOA_ERROR_STRENGTH = 3,   /* a strength the sampler cannot have */
    PYOA_ERROR_OFFSET = 4,     /* an unknown offset style, or one for a comparison sampler */
    PYOA_ERROR_RESOLUTION = 5, /* zsobol or zfaure without an image or too large a one; an image for another */
    PYOA_ERROR_DIMS = 6,       /* more dimensions than the sampler has */
    PYOA_ERROR_BASE = 7,       /* not a prime in [2, 4093] (zfaure: or not spp's); a base for another sampler */
    PYOA_ERROR_JITTER = 8      /* a jitter amount outside [0, 1], or one for a sampler without jitter */
};

#if !defined(__OPENCL_VERSION__)

#if defined(__cplusplus)
#include <cstddef>
#include <cstdio>
#else
#include <stddef.h>
#include <stdio.h>
#endif

/* Largest samples per pixel (pyoa.catalogue.entries.MAX_SPP = 2^24: every
 * integer that becomes a float is exact in float32) and largest number of
 * dimensions (MAX_DIMS = 2^20). */
#define PYOA_MAX_SPP 16777216u
#define PYOA_MAX_DIMS 1048576u
/* The codes PYOA_SAMPLER_<NAME> run from 0 to PYOA_SAMPLER_COUNT - 1. */
#define PYOA_SAMPLER_COUNT 15u
/* pyoa_sampler_offset's offset of a comparison sampler: it has none (the
 * Python API's None). */
#define PYOA_OFFSET_NONE 4u

/* Resolved parameters of one sampler: pyoa.catalogue.entries.Params, plus
 * the sampler's code and its count. As there:
 *   s           coarse strata per axis (an OA's order; faure's and zfaure's
 *               base; the comparison samplers' grids as pyoa.catalogue.baselines
 *               documents);
 *   strength    t (0 for random, halton and sobol; faure and zfaure: the
 *               largest m with s^m <= spp);
 *   block_dims  dimensions per independently randomized block;
 *   M           spp / s for the OAs (fine sub-strata per coarse stratum);
 *               the comparison samplers' own (spp, or cmj2d's n of m x n);
 *   dims        the dimensions asked for, 0 where unknown, as there: only
 *               the comparison samplers, faure and zfaure keep it (0 for
 *               the OAs);
 *   width, height  the image of zsobol and zfaure, 0 x 0 for the others. */
typedef struct pyoa_params {
    pyoa_u32 code, spp, s, strength, block_dims, M, dims, width, height;
} pyoa_params;

/* --------------------------------------------------------------- messages */

/* A message being written into a caller's buffer: `len` counts every
 * character written so far, stored or not (as snprintf's return value);
 * `buf` holds the first size - 1 of them and a terminating 0. buf NULL or
 * size 0: nothing is stored. */
typedef struct pyoa_text {
    char *buf;
    size_t size, len;
} pyoa_text;

PYOA_HOST_FN pyoa_text pyoa_text_start(char *buf, size_t size)
{
    pyoa_text t;
    t.buf = buf;
    t.size = buf != NULL ? size : 0u;
    t.len = 0u;
    if (t.size != 0u)
        buf[0] = '\0';
    return t;
}

PYOA_HOST_FN void pyoa_text_char(pyoa_text *t, char c)
{
    if (t == NULL)
        return;
    if (t->len + 1u < t->size) {
        t->buf[t->len] = c;
        t->buf[t->len + 1u] = '\0';
    }
    t->len++;
}

PYOA_HOST_FN void pyoa_text_str(pyoa_text *t, const char *s)
{
    if (s == NULL)
        return;
    while (*s != '\0')
        pyoa_text_char(t, *s++);
}

PYOA_HOST_FN void pyoa_text_u32(pyoa_text *t, pyoa_u32 v)
{
    char digits[10];
    int n = 0;
    do {
        digits[n++] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0u);
    while (n > 0)
        pyoa_text_char(t, digits[--n]);
}

/* `s` as Python's repr() of a str writes it (the messages quote what the
 * user typed as {name!r}): in single quotes, or double quotes when it holds
 * a ' and no "; backslashes and the quote escaped, control bytes as \t,
 * \n, \r or \xNN. Bytes above 0x7f are copied (a UTF-8 string stays one). */
PYOA_HOST_FN void pyoa_text_repr(pyoa_text *t, const char *s)
{
    static const char hex[] = "0123456789abcdef";
    const char *p;
    char quote = '\'';
    int single = 0, dbl = 0;
    if (s == NULL) {
        pyoa_text_str(t, "None");
        return;
    }
    for (p = s; *p != '\0'; ++p) {
        single |= *p == '\'';
        dbl |= *p == '"';
    }
    if (single && !dbl)
        quote = '"';
    pyoa_text_char(t, quote);
    for (p = s; *p != '\0'; ++p) {
        unsigned char c = (unsigned char)*p;
        if (c == (unsigned char)quote || c == '\\') {
            pyoa_text_char(t, '\\');
            pyoa_text_char(t, (char)c);
        } else if (c == '\t' || c == '\n' || c == '\r') {
            pyoa_text_char(t, '\\');
            pyoa_text_char(t, c == '\t' ? 't' : c == '\n' ? 'n' : 'r');
        } else if (c < 0x20u || c == 0x7fu) {
            pyoa_text_str(t, "\\x");
            pyoa_text_char(t, hex[c >> 4]);
            pyoa_text_char(t, hex[c & 15u]);
        } else {
            pyoa_text_char(t, (char)c);
        }
    }
    pyoa_text_char(t, quote);
}

/* --------------------------------------------------------- integer helpers */

/* a^t, or 2^63 where that would be larger (every caller compares it with
 * a count below 2^57). */
PYOA_HOST_FN pyoa_u64 pyoa_counts_pow(pyoa_u64 a, pyoa_u32 t)
{
    const pyoa_u64 cap = (pyoa_u64)1u << 63;
    pyoa_u64 r = 1u;
    while (t-- > 0u) {
        if (a != 0u && r > cap / a)
            return cap;
        r *= a;
    }
    return r;
}

/* floor(n^(1/t)) for t >= 1, exactly (constructions.integer_root_floor). */
PYOA_HOST_FN pyoa_u64 pyoa_counts_root_floor(pyoa_u64 n, pyoa_u32 t)
{
    pyoa_u64 lo = 0u, hi = (pyoa_u64)1u << 32;
    if (t == 1u)
        return n;
    while (lo < hi) { /* the largest r in [0, 2^32) with r^t <= n (n < 2^56 here) */
        pyoa_u64 mid = lo + (hi - lo + 1u) / 2u;
        if (pyoa_counts_pow(mid, t) <= n)
            lo = mid;
        else
            hi = mid - 1u;
    }
    return lo;
}

/* s with s^t == n, s >= 1, or 0 when there is none (constructions.integer_root). */
PYOA_HOST_FN pyoa_u32 pyoa_counts_root(pyoa_u32 n, pyoa_u32 t)
{
    pyoa_u64 r = pyoa_counts_root_floor(n, t);
    return r >= 1u && pyoa_counts_pow(r, t) == n ? (pyoa_u32)r : 0u;
}

/* n^(1/t) rounded to the nearest integer: Python's int(round(n ** (1.0 / t)))
 * of constructions._power_candidates, computed exactly. With r its floor,
 * the root is past r + 1/2 iff 2^t n > (2r + 1)^t; a tie needs
 * (2r + 1)^t = 2^t n, impossible for t >= 2 (odd against even), and for
 * t = 1 the root is n itself. For n < 2^32 the float computation rounds the
 * same way (tests/test_c_counts.py checks every boundary). */
PYOA_HOST_FN pyoa_u64 pyoa_counts_root_round(pyoa_u32 n, pyoa_u32 t)
{
    pyoa_u64 r = pyoa_counts_root_floor(n, t);
    if (t == 1u)
        return r;
    return r + (pyoa_counts_pow(2u, t) * (pyoa_u64)n > pyoa_counts_pow(2u * r + 1u, t) ? 1u : 0u);
}

PYOA_HOST_FN pyoa_u32 pyoa_counts_isqrt(pyoa_u32 n)
{
    return (pyoa_u32)pyoa_counts_root_floor(n, 2u);
}

/* Python's int.bit_length(). */
PYOA_HOST_FN pyoa_u32 pyoa_counts_bit_length(pyoa_u32 v)
{
    pyoa_u32 n = 0u;
    while (v != 0u) {
        v >>= 1;
        n++;
    }
    return n;
}

/* -------------------------------------------------------------- the names */

/* The catalogue's name of sampler `code` (PYOA_SAMPLER_<NAME>), or NULL
 * for a code that is none. */
PYOA_HOST_FN const char *pyoa_sampler_name(pyoa_u32 code)
{
    switch (code) {
    case PYOA_SAMPLER_BOSE: return "bose";
    case PYOA_SAMPLER_CMJND: return "cmjnd";
    case PYOA_SAMPLER_BUSH: return "bush";
    case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE: return "addelman-kempthorne";
    case PYOA_SAMPLER_BOSE_BUSH: return "bose-bush";
    case PYOA_SAMPLER_RANDOM: return "random";
    case PYOA_SAMPLER_JITTERED2D: return "jittered2d";
    case PYOA_SAMPLER_CMJ2D: return "cmj2d";
    case PYOA_SAMPLER_SOBOL02: return "sobol02";
    case PYOA_SAMPLER_HALTON: return "halton";
    case PYOA_SAMPLER_SOBOL: return "sobol";
    case PYOA_SAMPLER_ZSOBOL: return "zsobol";
    case PYOA_SAMPLER_PMJ02: return "pmj02";
    case PYOA_SAMPLER_FAURE: return "faure";
    case PYOA_SAMPLER_ZFAURE: return "zfaure";
    default: return NULL;
    }
}

/* The k-th code in pyoa.catalogue.SAMPLERS's order (the OAs, then the
 * comparison samplers, then faure and zfaure), k < PYOA_SAMPLER_COUNT: the
 * order of the name lists in messages and of the registry within a family. */
PYOA_HOST_FN pyoa_u32 pyoa_counts_listed(pyoa_u32 k)
{
    switch (k) {
    case 0: return PYOA_SAMPLER_BOSE;
    case 1: return PYOA_SAMPLER_BUSH;
    case 2: return PYOA_SAMPLER_CMJND;
    case 3: return PYOA_SAMPLER_ADDELMAN_KEMPTHORNE;
    case 4: return PYOA_SAMPLER_BOSE_BUSH;
    default: return k; /* random (5) ... zfaure (14): their codes are their places */
    }
}

/* The k-th of pyoa.catalogue.ALIASES (pbrt-v4's and Mitsuba 3's names),
 * with the code it stands for; NULL past the last. */
PYOA_HOST_FN const char *pyoa_counts_alias(pyoa_u32 k, pyoa_u32 *code)
{
    switch (k) {
    case 0: *code = PYOA_SAMPLER_RANDOM; return "independent";
    case 1: *code = PYOA_SAMPLER_JITTERED2D; return "stratified";
    case 2: *code = PYOA_SAMPLER_CMJ2D; return "multijitter";
    case 3: *code = PYOA_SAMPLER_BOSE; return "orthogonal";
    case 4: *code = PYOA_SAMPLER_SOBOL02; return "paddedsobol";
    case 5: *code = PYOA_SAMPLER_SOBOL02; return "ldsampler";
    default: return NULL;
    }
}

/* Whether `typed`, lowered as Python's str.lower() lowers it, is `name`
 * (lower-case ASCII). Of all the characters outside ASCII, lower() takes
 * only the Kelvin sign U+212A (UTF-8 e2 84 aa) into ASCII ('k'): it is the
 * one non-ASCII spelling Python accepts ("addelman-\u212aempthorne"). */
PYOA_HOST_FN int pyoa_counts_same_name(const char *typed, const char *name)
{
    const unsigned char *p = (const unsigned char *)typed;
    for (; *name != '\0'; ++name) {
        unsigned char c = *p;
        if (c == 0xe2u && p[1] == 0x84u && p[2] == 0xaau) {
            c = 'k';
            p += 3;
        } else {
            if (c >= 'A' && c <= 'Z')
                c = (unsigned char)(c - 'A' + 'a');
            if (c == '\0')
                return 0;
            p++;
        }
        if (c != (unsigned char)*name)
            return 0;
    }
    return *p == '\0';
}

/* The code of the sampler named `name`: a catalogue name or an alias of
 * pyoa.catalogue.ALIASES ("independent" is random, "orthogonal" bose, ...),
 * in any case (catalogue.get). PYOA_OK, or PYOA_ERROR_NAME (`*code` left
 * as it was; pyoa_name_error writes the message). */
PYOA_HOST_FN int pyoa_lookup(const char *name, pyoa_u32 *code)
{
    pyoa_u32 k, c = 0u;
    const char *alias;
    if (name == NULL)
        return PYOA_ERROR_NAME;
    for (k = 0u; k < PYOA_SAMPLER_COUNT; ++k) {
        if (pyoa_counts_same_name(name, pyoa_sampler_name(k))) {
            *code = k;
            return PYOA_OK;
        }
    }
    for (k = 0u; (alias = pyoa_counts_alias(k, &c)) != NULL; ++k) {
        if (pyoa_counts_same_name(name, alias)) {
            *code = c;
            return PYOA_OK;
        }
    }
    return PYOA_ERROR_NAME;
}

/* catalogue.get's message for an unknown `name` ("unknown sampler 'x';
 * valid: bose, bush, ... (or the pbrt/Mitsuba names independent, ...)"),
 * into message[message_size] (snprintf's truncation). Returns the length of
 * the whole message, as snprintf does. */
PYOA_HOST_FN size_t pyoa_name_error(const char *name, char *message, size_t message_size)
{
    pyoa_text t = pyoa_text_start(message, message_size);
    pyoa_u32 k, c = 0u;
    const char *alias;
    pyoa_text_str(&t, "unknown sampler ");
    pyoa_text_repr(&t, name);
    pyoa_text_str(&t, "; valid: ");
    for (k = 0u; k < PYOA_SAMPLER_COUNT; ++k) {
        pyoa_text_str(&t, k ? ", " : "");
        pyoa_text_str(&t, pyoa_sampler_name(pyoa_counts_listed(k)));
    }
    pyoa_text_str(&t, " (or the pbrt/Mitsuba names ");
    for (k = 0u; (alias = pyoa_counts_alias(k, &c)) != NULL; ++k) {
        pyoa_text_str(&t, k ? ", " : "");
        pyoa_text_str(&t, alias);
    }
    pyoa_text_char(&t, ')');
    return t.len;
}

/* ------------------------------------------------------ what each entry is */

/* The catalogue entry's family: 0 the orthogonal arrays (Construction.family
 * "oa"), 1 the comparison samplers ("baseline"), 2 faure and zfaure
 * ("progressive"). */
PYOA_HOST_FN int pyoa_counts_family(pyoa_u32 code)
{
    return code <= PYOA_SAMPLER_BOSE_BUSH ? 0 : code == PYOA_SAMPLER_FAURE || code == PYOA_SAMPLER_ZFAURE ? 2 : 1;
}

/* Whether sampler `code` needs the image (Construction.needs_resolution):
 * zsobol and zfaure. pyoa_solve refuses a width x height for every other,
 * as the Python API refuses resolution=, so a renderer passes
 * pyoa_needs_resolution(code) ? width : 0 (and the same for height). */
PYOA_HOST_FN int pyoa_needs_resolution(pyoa_u32 code)
{
    return code == PYOA_SAMPLER_ZSOBOL || code == PYOA_SAMPLER_ZFAURE;
}

/* The comparison samplers' Baseline.max_dims: halton one prime below 2^16
 * per dimension, sobol the Joe-Kuo table's 21201, the others MAX_DIMS. */
PYOA_HOST_FN pyoa_u32 pyoa_counts_max_dims(pyoa_u32 code)
{
    return code == PYOA_SAMPLER_HALTON ? 6542u : code == PYOA_SAMPLER_SOBOL ? 21201u : PYOA_MAX_DIMS;
}

/* Baseline.counts: 0 "any" (every count in [1, max_spp]), 1 "pow2", 2 "square". */
PYOA_HOST_FN int pyoa_counts_kind(pyoa_u32 code)
{
    switch (code) {
    case PYOA_SAMPLER_JITTERED2D: return 2;
    case PYOA_SAMPLER_SOBOL02: case PYOA_SAMPLER_SOBOL: case PYOA_SAMPLER_ZSOBOL: case PYOA_SAMPLER_PMJ02: return 1;
    default: return 0;
    }
}

/* Baseline.max_spp: pmj02's tables hold 2^16 points, the others MAX_SPP. */
PYOA_HOST_FN pyoa_u32 pyoa_counts_max_spp(pyoa_u32 code)
{
    return code == PYOA_SAMPLER_PMJ02 ? 65536u : PYOA_MAX_SPP;
}

/* Bose's largest s: the largest prime with s^2 <= 2^24 (Bose.max_s). */
#define PYOA_COUNTS_BOSE_MAX_S 4093u
/* Addelman-Kempthorne's q run over odd prime powers up to isqrt(2^24 / 2). */
#define PYOA_COUNTS_AK_MAX_Q 2896u
/* ... of which the largest is the prime 2887 (the messages name it). */
#define PYOA_COUNTS_AK_LAST 2887u
/* faure's largest base (reference.faure.MAX_BASE): the largest prime b with b^2 <= 2^24. */
#define PYOA_COUNTS_MAX_BASE 4093u
/* zfaure's largest image side (reference.zfaure.MAX_RESOLUTION), as zsobol's. */
#define PYOA_COUNTS_MAX_RESOLUTION 65536u

PYOA_HOST_FN void pyoa_counts_set(pyoa_params *p, pyoa_u32 code, pyoa_u32 spp, pyoa_u32 s, pyoa_u32 strength,
                                  pyoa_u32 block_dims, pyoa_u32 M, pyoa_u32 dims)
{
    p->code = code;
    p->spp = spp;
    p->s = s;
    p->strength = strength;
    p->block_dims = block_dims;
    p->M = M;
    p->dims = dims;
    p->width = 0u;
    p->height = 0u;
}

/* The array with s symbols and strength t of an OA construction: its
 * reference.oa.*_geometry (N, B, s, M) as Params (_OA.params_for, whose
 * dims is 0: no OA depends on it). */
PYOA_HOST_FN void pyoa_counts_oa(pyoa_params *p, pyoa_u32 code, pyoa_u32 s, pyoa_u32 t, pyoa_u32 dims)
{
    pyoa_u32 sm = (pyoa_u32)pyoa_counts_pow(s, t - 1u);
    dims = 0u;
    switch (code) {
    case PYOA_SAMPLER_BOSE: pyoa_counts_set(p, code, s * s, s, 2u, s + 1u, s, dims); break;
    case PYOA_SAMPLER_BUSH: pyoa_counts_set(p, code, sm * s, s, t, s + 1u, sm, dims); break;
    case PYOA_SAMPLER_CMJND: pyoa_counts_set(p, code, sm * s, s, t, t, sm, dims); break;
    default: pyoa_counts_set(p, code, 2u * s * s, s, 2u, 2u * s + 1u, 2u * s, dims); break; /* index 2 */
    }
}

/* progressive.default_base: the largest prime b with b^2 <= spp (2 below 4
 * samples), or the smallest prime >= dims when that is no larger. */
PYOA_HOST_FN pyoa_u32 pyoa_counts_default_base(pyoa_u32 spp, pyoa_u32 dims)
{
    pyoa_u32 root = pyoa_counts_isqrt(spp > 1u ? spp : 1u), b_max = 2u, fits;
    if (root > PYOA_COUNTS_MAX_BASE)
        root = PYOA_COUNTS_MAX_BASE;
    for (; root >= 2u; --root) {
        if (pyoa_is_prime(root)) {
            b_max = root;
            break;
        }
    }
    if (dims != 0u && dims <= PYOA_COUNTS_MAX_BASE) {
        for (fits = dims; !pyoa_is_prime(fits); ++fits) {
        }
        if (fits <= b_max) /* also bounds fits by MAX_BASE */
            return fits;
    }
    return b_max;
}

/* progressive._levels: the largest m with b^m <= spp. */
PYOA_HOST_FN pyoa_u32 pyoa_counts_levels(pyoa_u32 b, pyoa_u32 spp)
{
    pyoa_u32 m = 0u;
    pyoa_u64 power = b;
    while (power <= spp) {
        m++;
        power *= b;
    }
    return m;
}

/* Whether spp is a count of zfaure (catalogue.faure.zfaure_counts): b^m
 * for a prime b and m >= 2, up to 2^24 (so b <= 4093). Then *b and *m are
 * set: b is spp's smallest prime factor, and spp a power of it. */
PYOA_HOST_FN int pyoa_counts_zfaure_power(pyoa_u32 spp, pyoa_u32 *b, pyoa_u32 *m)
{
    pyoa_u32 p, rest, e = 0u;
    if (spp < 4u || spp > PYOA_MAX_SPP)
        return 0;
    for (p = 2u; p * p <= spp && spp % p != 0u; ++p) {
    }
    if (p * p > spp) /* spp is a prime: m = 1 */
        return 0;
    for (rest = spp; rest % p == 0u; rest /= p)
        e++;
    if (rest != 1u)
        return 0;
    *b = p;
    *m = e;
    return 1;
}

/* Whether spp is a count of zfaure (ZFaure.valid). */
PYOA_HOST_FN int pyoa_counts_zfaure_valid(pyoa_u32 spp)
{
    pyoa_u32 b, m;
    return pyoa_counts_zfaure_power(spp, &b, &m);
}

/* reference.zfaure.grid_digits: the fewest k with b^k >= max(width, height)
 * (0 for one pixel). */
PYOA_HOST_FN pyoa_u32 pyoa_counts_grid_digits(pyoa_u32 b, pyoa_u32 width, pyoa_u32 height)
{
    pyoa_u32 k = 0u, side = width > height ? width : height;
    for (pyoa_u64 power = 1u; power < side; power *= b)
        k++;
    return k;
}

/* reference.zfaure.check_shape's 64-bit limit: whether b^(2k) N <= 2^64,
 * exactly. b^k < b 2^16 <= 2^28, so x = b^(2k) < 2^56, and x N < 2^80 is
 * summed in 32-bit halves: x N = hi 2^32 + lo with lo < 2^32. */
PYOA_HOST_FN int pyoa_counts_zfaure_fits(pyoa_u32 N, pyoa_u32 b, pyoa_u32 k)
{
    const pyoa_u64 two32 = (pyoa_u64)1u << 32;
    pyoa_u64 x = pyoa_counts_pow(b, 2u * k);
    pyoa_u64 lo = (x & 0xffffffffu) * N, hi = (x >> 32) * N + (lo >> 32);
    lo &= 0xffffffffu;
    return hi < two32 || (hi == two32 && lo == 0u);
}

/* Baseline.params (and each subclass's) of a valid count. */
PYOA_HOST_FN void pyoa_counts_baseline(pyoa_params *p, pyoa_u32 code, pyoa_u32 spp, pyoa_u32 dims)
{
    pyoa_u32 m, b;
    switch (code) {
    case PYOA_SAMPLER_RANDOM: pyoa_counts_set(p, code, spp, 1u, 0u, 1u, spp, dims); break;
    case PYOA_SAMPLER_JITTERED2D:
        m = pyoa_counts_isqrt(spp);
        pyoa_counts_set(p, code, spp, m, 2u, 2u, 1u, dims);
        break;
    case PYOA_SAMPLER_CMJ2D: /* the most nearly square grid m x n: m the largest divisor <= sqrt(spp) */
        for (m = pyoa_counts_isqrt(spp); m > 1u && spp % m != 0u; --m) {
        }
        pyoa_counts_set(p, code, spp, m, 2u, 2u, spp / m, dims);
        break;
    case PYOA_SAMPLER_SOBOL02: case PYOA_SAMPLER_ZSOBOL: case PYOA_SAMPLER_PMJ02:
        pyoa_counts_set(p, code, spp, 2u, 2u, 2u, spp, dims);
        break;
    case PYOA_SAMPLER_FAURE:
        b = pyoa_counts_default_base(spp, dims);
        pyoa_counts_set(p, code, spp, b, pyoa_counts_levels(b, spp), b, spp, dims);
        break;
    case PYOA_SAMPLER_ZFAURE: /* ZFaure.params: the count fixes the base */
        m = 0u;
        b = 2u;
        (void)pyoa_counts_zfaure_power(spp, &b, &m);
        pyoa_counts_set(p, code, spp, b, m, b, spp, dims);
        break;
    default: /* halton, sobol: Baseline.params */
        pyoa_counts_set(p, code, spp, 1u, 0u, pyoa_counts_max_dims(code), spp, dims);
        break;
    }
}

/* The strengths an OA entry tries for a count (Bush._strengths,
 * CMJND._strengths), as the range [*lo, *hi], in increasing order. */
PYOA_HOST_FN void pyoa_counts_strengths(pyoa_u32 code, pyoa_u32 dims, pyoa_u32 strength, pyoa_u32 *lo, pyoa_u32 *hi)
{
    if (strength != 0u) {
        *lo = *hi = strength;
    } else if (code == PYOA_SAMPLER_BUSH) { /* 2 .. max(2, min(dims or 8, 8)) */
        *lo = 2u;
        *hi = dims == 0u || dims > 8u ? 8u : dims < 2u ? 2u : dims;
    } else if (dims == 1u) { /* cmjnd with one dimension: strength 1, any count */
        *lo = *hi = 1u;
    } else {
        *lo = 2u;
        *hi = dims == 0u || dims > 24u ? 24u : dims;
    }
}

/* Whether s symbols at strength t make an array of an OA entry that
 * accepts N = s^t (Bush: s >= t a supported field; CMJND: s >= 2). */
PYOA_HOST_FN int pyoa_counts_power_ok(pyoa_u32 code, pyoa_u32 s, pyoa_u32 t)
{
    return code == PYOA_SAMPLER_BUSH ? s >= t && pyoa_gf_is_supported(s) : s >= 2u;
}

/* Whether x is a level of an index-2 array: Addelman-Kempthorne's odd
 * prime powers up to 2896, Bose-Bush's 2, 4, ..., 128. */
PYOA_HOST_FN int pyoa_counts_index2_level(pyoa_u32 code, pyoa_u32 x)
{
    if (code == PYOA_SAMPLER_ADDELMAN_KEMPTHORNE)
        return x >= 3u && x <= PYOA_COUNTS_AK_MAX_Q && x % 2u == 1u && pyoa_gf_is_supported(x);
    return x >= 2u && x <= 128u && (x & (x - 1u)) == 0u;
}

/* Construction.solve(spp, dims, strength) (dims and strength 0: None): 0
 * and the parameters in *out for a valid count; -1 for a count that is not
 * valid (Python's None); an error code, its message written to t (may be
 * NULL), where Python raises (a strength the entry cannot have; more dims
 * than a comparison sampler has). */
PYOA_HOST_FN int pyoa_counts_solve(pyoa_u32 code, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 strength, pyoa_params *out,
                                   pyoa_text *t)
{
    const char *name = pyoa_sampler_name(code);
    pyoa_u32 s, lo, hi, k;
    if (pyoa_counts_family(code) != 0) { /* Baseline._check, then Baseline.valid */
        if (strength != 0u) {
            pyoa_text_str(t, name);
            pyoa_text_str(t, " has no strength parameter (got strength=");
            pyoa_text_u32(t, strength);
            pyoa_text_str(t, "); strength applies to the orthogonal-array samplers");
            return PYOA_ERROR_STRENGTH;
        }
        if (dims != 0u && dims > pyoa_counts_max_dims(code)) {
            pyoa_text_str(t, name);
            pyoa_text_str(t, " supports at most ");
            pyoa_text_u32(t, pyoa_counts_max_dims(code));
            pyoa_text_str(t, " dimensions, got dims=");
            pyoa_text_u32(t, dims);
            if (code == PYOA_SAMPLER_HALTON)
                pyoa_text_str(t, " (one prime base below 2^16 each); use sobol (21201) or a padded sampler for more");
            else if (code == PYOA_SAMPLER_SOBOL)
                pyoa_text_str(t, " (the Joe-Kuo table); use a padded sampler for more");
            return PYOA_ERROR_DIMS;
        }
        if (spp < 1u || spp > pyoa_counts_max_spp(code))
            return -1;
        if (pyoa_counts_kind(code) == 1 && (spp & (spp - 1u)) != 0u)
            return -1;
        if (pyoa_counts_kind(code) == 2 && pyoa_counts_isqrt(spp) * pyoa_counts_isqrt(spp) != spp)
            return -1;
        if (code == PYOA_SAMPLER_ZFAURE && !pyoa_counts_zfaure_valid(spp))
            return -1; /* ZFaure.valid: b^m, b a prime, m >= 2 */
        pyoa_counts_baseline(out, code, spp, dims);
        return 0;
    }
    switch (code) {
    case PYOA_SAMPLER_BOSE:
        if (strength != 0u && strength != 2u) {
            pyoa_text_str(t, "bose has strength 2 only (got strength=");
            pyoa_text_u32(t, strength);
            pyoa_text_str(t, "); use 'bush' or 'cmjnd' for strength t >= 3 (N = s^t)");
            return PYOA_ERROR_STRENGTH;
        }
        s = pyoa_counts_isqrt(spp);
        if (s * s != spp || !pyoa_gf_is_supported(s) || s > PYOA_COUNTS_BOSE_MAX_S)
            return -1;
        pyoa_counts_oa(out, code, s, 2u, dims);
        return 0;
    case PYOA_SAMPLER_BUSH:
    case PYOA_SAMPLER_CMJND:
        if (strength != 0u && (code == PYOA_SAMPLER_BUSH ? strength < 2u || strength > 8u : strength > 24u)) {
            if (code == PYOA_SAMPLER_BUSH) {
                pyoa_text_str(t, "bush strength must be an integer in [2, 8] (t <= s and s^t <= 2^24), got ");
                pyoa_text_u32(t, strength);
                pyoa_text_str(t, "; use 'cmjnd' for higher strengths");
            } else {
                pyoa_text_str(t, "cmjnd strength must be an integer in [1, 24], got ");
                pyoa_text_u32(t, strength);
            }
            return PYOA_ERROR_STRENGTH;
        }
        /* the largest strength that makes spp = s^t: the most dimensions stratified jointly */
        pyoa_counts_strengths(code, dims, strength, &lo, &hi);
        for (k = hi; k >= lo; --k) {
            s = pyoa_counts_root(spp, k);
            if (s != 0u && pyoa_counts_power_ok(code, s, k)) {
                pyoa_counts_oa(out, code, s, k, dims);
                return 0;
            }
        }
        return -1;
    default: /* Addelman-Kempthorne, Bose-Bush: N = 2 s^2 */
        if (strength != 0u && strength != 2u) {
            pyoa_text_str(t, name);
            pyoa_text_str(t, " has strength 2 only (got strength=");
            pyoa_text_u32(t, strength);
            pyoa_text_char(t, ')');
            return PYOA_ERROR_STRENGTH;
        }
        s = pyoa_counts_isqrt(spp / 2u);
        if (spp % 2u != 0u || 2u * s * s != spp || !pyoa_counts_index2_level(code, s))
            return -1;
        pyoa_counts_oa(out, code, s, 2u, dims);
        return 0;
    }
}

/* ------------------------------------------------------- the nearest counts */

/* Most choices pyoa_nearest can return: at most three counts, each by one
 * choice for all entries but bush and cmjnd, whose counts may be powers at
 * several strengths (64 = 8^2 = 4^3 = 2^6): one per strength, 23 at most. */
#define PYOA_NEAREST_MAX 72u
/* Most candidates considered: four per strength (constructions._power_candidates). */
#define PYOA_COUNTS_CANDIDATES 100u

/* A monotone family of one parameter x in [lo, hi], count(x) increasing:
 * bose's s (s^2), the index-2 arrays' s (2 s^2; Bose-Bush's s = 2^x),
 * jittered2d's m (m^2), the powers of two's k (2^k). */
PYOA_HOST_FN pyoa_u64 pyoa_counts_step_count(pyoa_u32 code, pyoa_u32 x)
{
    switch (code) {
    case PYOA_SAMPLER_BOSE: case PYOA_SAMPLER_JITTERED2D: return (pyoa_u64)x * x;
    case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE: return 2u * (pyoa_u64)x * x;
    case PYOA_SAMPLER_BOSE_BUSH: return 2u * ((pyoa_u64)1u << (2u * x));
    default: return (pyoa_u64)1u << x;
    }
}

PYOA_HOST_FN int pyoa_counts_step_ok(pyoa_u32 code, pyoa_u32 x)
{
    switch (code) {
    case PYOA_SAMPLER_BOSE: return pyoa_gf_is_supported(x);
    case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE: return pyoa_counts_index2_level(code, x);
    default: return 1;
    }
}

/* The choice of parameter x of a monotone family (for its listing). */
PYOA_HOST_FN void pyoa_counts_step_choice(pyoa_params *p, pyoa_u32 code, pyoa_u32 x, pyoa_u32 dims)
{
    if (code == PYOA_SAMPLER_BOSE || code == PYOA_SAMPLER_ADDELMAN_KEMPTHORNE)
        pyoa_counts_oa(p, code, x, 2u, dims);
    else if (code == PYOA_SAMPLER_BOSE_BUSH)
        pyoa_counts_oa(p, code, 1u << x, 2u, dims);
    else
        pyoa_counts_baseline(p, code, (pyoa_u32)pyoa_counts_step_count(code, x), dims);
}

/* catalogue_types.nearest over `n` candidate choices, in place: keeps the
 * choices of the largest count below spp, of spp and of the smallest count
 * above (both sides, not the two closest), in increasing count, candidates
 * of one count in their order (Python's stable sort). Returns how many. */
PYOA_HOST_FN size_t pyoa_counts_keep_nearest(pyoa_params *c, size_t n, pyoa_u32 spp)
{
    size_t i, j, kept = 0u;
    int has_below = 0, has_above = 0;
    pyoa_u32 below = 0u, above = 0u;
    for (i = 0u; i < n; ++i) {
        if (c[i].spp < spp && (!has_below || c[i].spp > below)) {
            below = c[i].spp;
            has_below = 1;
        }
        if (c[i].spp > spp && (!has_above || c[i].spp < above)) {
            above = c[i].spp;
            has_above = 1;
        }
    }
    for (i = 0u; i < n; ++i)
        if (c[i].spp == spp || (has_below && c[i].spp == below) || (has_above && c[i].spp == above))
            c[kept++] = c[i];
    for (i = 1u; i < kept; ++i) { /* insertion sort: stable */
        pyoa_params x = c[i];
        for (j = i; j > 0u && c[j - 1u].spp > x.spp; --j)
            c[j] = c[j - 1u];
        c[j] = x;
    }
    return kept;
}

/* The candidates of Construction.nearest for each entry, before
 * pyoa_counts_keep_nearest; returns how many (at most
 * PYOA_COUNTS_CANDIDATES). Arguments as checked by pyoa_counts_solve. */
PYOA_HOST_FN size_t pyoa_counts_candidates(pyoa_u32 code, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 strength,
                                           pyoa_params *c)
{
    size_t n = 0u;
    pyoa_u32 lo, hi, t, x, near, max_spp;
    if (code == PYOA_SAMPLER_BUSH || code == PYOA_SAMPLER_CMJND) {
        /* _power_candidates: per strength, the two valid s at or below the
         * rounded root (down to 2) and the two above it (up to s_max) */
        pyoa_counts_strengths(code, dims, strength, &lo, &hi);
        for (t = lo; t <= hi; ++t) {
            pyoa_u32 s_max = (pyoa_u32)pyoa_counts_root_floor(PYOA_MAX_SPP, t), found = 0u, s;
            pyoa_u64 root = pyoa_counts_root_round(spp > 1u ? spp : 1u, t);
            root = root < 2u ? 2u : root > s_max ? s_max : root;
            for (s = (pyoa_u32)root; s > 1u && found < 2u; --s)
                if (pyoa_counts_power_ok(code, s, t)) {
                    pyoa_counts_oa(&c[n++], code, s, t, dims);
                    found++;
                }
            for (s = (pyoa_u32)root + 1u, found = 0u; s <= s_max && found < 2u; ++s)
                if (pyoa_counts_power_ok(code, s, t)) {
                    pyoa_counts_oa(&c[n++], code, s, t, dims);
                    found++;
                }
        }
        return n;
    }
    if (code == PYOA_SAMPLER_ZFAURE) {
        /* ZFaure.nearest over its counts, the prime powers b^m (m >= 2) of
         * each base: the largest below spp, spp if one, the smallest above */
        pyoa_u32 below = 0u, above = 0u, b;
        for (b = 2u; b <= PYOA_COUNTS_MAX_BASE; ++b) {
            pyoa_u64 power;
            if (!pyoa_is_prime(b))
                continue;
            for (power = (pyoa_u64)b * b; power <= PYOA_MAX_SPP; power *= b) {
                if (power < spp && power > below)
                    below = (pyoa_u32)power;
                if (power > spp && (above == 0u || power < above))
                    above = (pyoa_u32)power;
            }
        }
        for (x = 0u; x < 3u; ++x) {
            pyoa_u32 count = x == 0u ? below : x == 1u ? spp : above;
            if (count != 0u && (x != 1u || pyoa_counts_zfaure_valid(spp)))
                pyoa_counts_baseline(&c[n++], code, count, dims);
        }
        return n;
    }
    if (pyoa_counts_family(code) != 0 && pyoa_counts_kind(code) == 0) {
        /* every count in [1, max_spp]: spp's neighbours (Baseline.nearest) */
        max_spp = pyoa_counts_max_spp(code);
        near = spp > max_spp ? max_spp + 1u : spp;
        for (x = near == 0u ? 0u : near - 1u; x <= near + 1u; ++x)
            if (x >= 1u && x <= max_spp)
                pyoa_counts_baseline(&c[n++], code, x, dims);
        return n;
    }
    /* a monotone family: the valid x just below spp's, spp's own, the one above */
    if (code == PYOA_SAMPLER_BOSE) {
        lo = 2u;
        hi = PYOA_COUNTS_BOSE_MAX_S;
    } else if (code == PYOA_SAMPLER_ADDELMAN_KEMPTHORNE) {
        lo = 3u;
        hi = PYOA_COUNTS_AK_MAX_Q;
    } else if (code == PYOA_SAMPLER_BOSE_BUSH) {
        lo = 1u;
        hi = 7u;
    } else if (code == PYOA_SAMPLER_JITTERED2D) {
        lo = 1u;
        hi = 4096u;
    } else { /* powers of two up to max_spp */
        lo = 0u;
        hi = pyoa_counts_bit_length(pyoa_counts_max_spp(code)) - 1u;
    }
    /* x: the first parameter whose count is >= spp (hi + 1 if none) */
    {
        pyoa_u32 a = lo, b = hi + 1u;
        while (a < b) {
            pyoa_u32 mid = a + (b - a) / 2u;
            if (pyoa_counts_step_count(code, mid) >= spp)
                b = mid;
            else
                a = mid + 1u;
        }
        x = a;
    }
    for (t = x; t > lo;) /* below */
        if (pyoa_counts_step_ok(code, --t)) {
            pyoa_counts_step_choice(&c[n++], code, t, dims);
            break;
        }
    for (t = x; t <= hi; ++t) /* spp itself, if valid, and above */
        if (pyoa_counts_step_ok(code, t)) {
            pyoa_counts_step_choice(&c[n++], code, t, dims);
            if (pyoa_counts_step_count(code, t) > spp)
                break;
        }
    return n;
}

/* The valid choices nearest `spp` on both sides (Construction.nearest, as
 * catalogue.valid_spp(name, near=spp, dims, strength) lists them): those of
 * the largest valid count below spp, of spp itself if valid, of the
 * smallest above, in increasing count; bush and cmjnd may list one count at
 * several strengths. dims, strength 0: not given. Writes up to `max` into
 * out (out may be NULL when max is 0) and returns how many there are (at
 * most PYOA_NEAREST_MAX), or 0 for an unknown code or a strength or dims
 * the sampler cannot have (valid_spp raises there). */
PYOA_HOST_FN size_t pyoa_nearest(pyoa_u32 code, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 strength, pyoa_params *out,
                                 size_t max)
{
    pyoa_params c[PYOA_COUNTS_CANDIDATES];
    size_t n, k;
    if (code >= PYOA_SAMPLER_COUNT || dims > PYOA_MAX_DIMS || pyoa_counts_solve(code, 1u, dims, strength, c, NULL) > 0)
        return 0u;
    n = pyoa_counts_keep_nearest(c, pyoa_counts_candidates(code, spp, dims, strength, c), spp);
    for (k = 0u; k < n && k < max; ++k)
        out[k] = c[k];
    return n;
}

/* catalogue.nearest_spp: the valid count closest to spp (spp itself if
 * valid; a tie goes to fewer samples), or 0 if there is none (an unknown
 * code, or a strength or dims the sampler cannot have). */
PYOA_HOST_FN pyoa_u32 pyoa_nearest_spp(pyoa_u32 code, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 strength)
{
    pyoa_params c[PYOA_NEAREST_MAX];
    size_t n = pyoa_nearest(code, spp, dims, strength, c, PYOA_NEAREST_MAX), k;
    pyoa_u32 best = 0u;
    pyoa_u64 best_d = 0u;
    for (k = 0u; k < n; ++k) {
        pyoa_u64 d = c[k].spp > spp ? (pyoa_u64)c[k].spp - spp : (pyoa_u64)spp - c[k].spp;
        if (best == 0u || d < best_d || (d == best_d && c[k].spp < best)) {
            best = c[k].spp;
            best_d = d;
        }
    }
    return best;
}

/* What SppChoice.label() writes inside its parentheses, "" where it writes
 * none: a comparison sampler's detail ("2^7", "11x11", "10x12", "b=5") or,
 * without one, nothing for strength 0; "s=11" at strength 2, "s=5, t=3"
 * otherwise. Returns whether it wrote anything. */
PYOA_HOST_FN int pyoa_counts_inner(pyoa_text *t, const pyoa_params *c)
{
    switch (pyoa_counts_family(c->code) == 0 ? -1 : (int)c->code) {
    case PYOA_SAMPLER_JITTERED2D:
        pyoa_text_u32(t, c->s);
        pyoa_text_char(t, 'x');
        pyoa_text_u32(t, c->s);
        return 1;
    case PYOA_SAMPLER_CMJ2D:
        pyoa_text_u32(t, c->s);
        pyoa_text_char(t, 'x');
        pyoa_text_u32(t, c->M);
        return 1;
    case PYOA_SAMPLER_FAURE: case PYOA_SAMPLER_ZFAURE:
        pyoa_text_str(t, "b=");
        pyoa_text_u32(t, c->s);
        return 1;
    case PYOA_SAMPLER_SOBOL02: case PYOA_SAMPLER_SOBOL: case PYOA_SAMPLER_ZSOBOL: case PYOA_SAMPLER_PMJ02:
        pyoa_text_str(t, "2^");
        pyoa_text_u32(t, pyoa_counts_bit_length(c->M) - 1u);
        return 1;
    default:
        if (c->strength == 0u)
            return 0;
        pyoa_text_str(t, "s=");
        pyoa_text_u32(t, c->s);
        if (c->strength != 2u) {
            pyoa_text_str(t, ", t=");
            pyoa_text_u32(t, c->strength);
        }
        return 1;
    }
}

/* Whether pyoa_counts_inner writes something for c. */
PYOA_HOST_FN int pyoa_counts_has_inner(const pyoa_params *c)
{
    pyoa_text none = pyoa_text_start(NULL, 0u);
    return pyoa_counts_inner(&none, c);
}

/* SppChoice.label(): "121 (s=11)", "125 (s=5, t=3)", "128 (2^7)", "7". */
PYOA_HOST_FN void pyoa_counts_label(pyoa_text *t, const pyoa_params *c)
{
    pyoa_text_u32(t, c->spp);
    if (pyoa_counts_has_inner(c)) {
        pyoa_text_str(t, " (");
        pyoa_counts_inner(t, c);
        pyoa_text_char(t, ')');
    }
}

/* "; nearest: 81 (s=9), 121 (s=11)" (catalogue_types._labels). */
PYOA_HOST_FN void pyoa_counts_nearest_text(pyoa_text *t, pyoa_u32 code, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 strength)
{
    pyoa_params c[PYOA_NEAREST_MAX];
    size_t n = pyoa_nearest(code, spp, dims, strength, c, PYOA_NEAREST_MAX), k;
    pyoa_text_str(t, "; nearest: ");
    for (k = 0u; k < n; ++k) {
        pyoa_text_str(t, k ? ", " : "");
        pyoa_counts_label(t, &c[k]);
    }
}

/* Construction.invalid: why spp is not a valid count. */
PYOA_HOST_FN void pyoa_counts_invalid(pyoa_text *t, pyoa_u32 code, pyoa_u32 spp, pyoa_u32 dims, pyoa_u32 strength)
{
    pyoa_u32 lo, hi;
    pyoa_text_u32(t, spp);
    switch (code) {
    case PYOA_SAMPLER_BOSE:
        pyoa_text_str(t, " is not s^2 with s a prime (<= 4093) or a prime power (<= 256)");
        return;
    case PYOA_SAMPLER_BUSH:
        pyoa_counts_strengths(code, dims, strength, &lo, &hi);
        pyoa_text_str(t, " is not s^");
        if (strength != 0u) {
            pyoa_text_u32(t, strength);
        } else {
            pyoa_text_str(t, "t for any strength 2 <= t <= ");
            pyoa_text_u32(t, hi);
        }
        pyoa_text_str(t, " with s >= t a prime, or a prime power <= 256");
        return;
    case PYOA_SAMPLER_CMJND:
        pyoa_text_str(t, " is not s^");
        if (strength != 0u) {
            pyoa_text_u32(t, strength);
            pyoa_text_str(t, " with s >= 2");
            return;
        }
        pyoa_counts_strengths(code, dims, 0u, &lo, &hi);
        pyoa_text_str(t, "t with s >= 2 for any strength ");
        pyoa_text_u32(t, lo);
        pyoa_text_str(t, " <= t <= ");
        pyoa_text_u32(t, hi);
        pyoa_text_str(t, " (dims=");
        if (dims != 0u)
            pyoa_text_u32(t, dims);
        else
            pyoa_text_str(t, "None");
        pyoa_text_char(t, ')');
        return;
    case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE:
        pyoa_text_str(t, " is not 2q^2 with q an odd prime (<= 2887) or odd prime power (<= 256)");
        return;
    case PYOA_SAMPLER_BOSE_BUSH:
        pyoa_text_str(t, " is not 2s^2 with s a power of two (<= 128, GF(2s) tables up to 256)");
        return;
    case PYOA_SAMPLER_JITTERED2D:
        pyoa_text_str(t, " is not a square m^2 (m <= 4096)");
        return;
    case PYOA_SAMPLER_ZFAURE:
        pyoa_text_str(t, " is not a power b^m of a prime b with m >= 2 (4, 8, 9, 16, 25, 27, 32, ...) up to 2^24");
        return;
    default:
        if (pyoa_counts_kind(code) == 1) {
            pyoa_text_str(t, " is not a power of two in [1, 2^");
            pyoa_text_u32(t, pyoa_counts_bit_length(pyoa_counts_max_spp(code)) - 1u);
            pyoa_text_char(t, ']');
        } else {
            pyoa_text_str(t, " is not in [1, 2^24]");
        }
        return;
    }
}

/* catalogue_types._elsewhere: "; 64 is valid for bush (s=4, t=3), cmjnd (s=8)":
 * the other entries of the same family that accept spp (strength not
 * given), in registration order; nothing when none does. */
PYOA_HOST_FN void pyoa_counts_elsewhere(pyoa_text *t, pyoa_u32 code, pyoa_u32 spp, pyoa_u32 dims)
{
    pyoa_u32 k, other;
    int found = 0;
    for (k = 0u; k < PYOA_SAMPLER_COUNT; ++k) {
        pyoa_params p;
        other = pyoa_counts_listed(k);
        if (other == code || pyoa_counts_family(other) != pyoa_counts_family(code)
            || pyoa_counts_solve(other, spp, dims, 0u, &p, NULL) != 0)
            continue;
        if (!found) {
            pyoa_text_str(t, "; ");
            pyoa_text_u32(t, spp);
            pyoa_text_str(t, " is valid for ");
        } else {
            pyoa_text_str(t, ", ");
        }
        found = 1;
        pyoa_text_str(t, pyoa_sampler_name(other));
        if (pyoa_counts_has_inner(&p)) {
            pyoa_text_str(t, " (");
            pyoa_counts_inner(t, &p);
            pyoa_text_char(t, ')');
        }
    }
}

/* ------------------------------------------------------------ the offsets */

/* The name of offset style `code` (reference.oa.OFFSETS), or NULL. */
PYOA_HOST_FN const char *pyoa_offset_name(pyoa_u32 code)
{
    switch (code) {
    case PYOA_OFFSET_CENTERED: return "centered";
    case PYOA_OFFSET_J: return "j";
    case PYOA_OFFSET_MJ: return "mj";
    case PYOA_OFFSET_CMJ: return "cmj";
    default: return NULL;
    }
}

/* The code PYOA_OFFSET_<NAME> of the offset style `offset` of the OA
 * samplers (docs/spec.md section 4): "centered", "j", "mj" or "cmj",
 * exactly (the Python API takes no other spelling); NULL is the default,
 * "cmj". PYOA_OK, or PYOA_ERROR_OFFSET (`*code` left as it was). */
PYOA_HOST_FN int pyoa_offset_code(const char *offset, pyoa_u32 *code)
{
    pyoa_u32 k;
    if (offset == NULL) {
        *code = PYOA_OFFSET_CMJ;
        return PYOA_OK;
    }
    for (k = 0u; k < 4u; ++k) {
        if (strcmp(offset, pyoa_offset_name(k)) == 0) {
            *code = k;
            return PYOA_OK;
        }
    }
    return PYOA_ERROR_OFFSET;
}

/* samplers._offset: the offset of sampler `sampler_code` given `offset`.
 * The OA samplers: pyoa_offset_code's; the comparison samplers, faure and
 * zfaure have none: NULL gives PYOA_OFFSET_NONE, anything else is refused. On
 * error (PYOA_ERROR_OFFSET; PYOA_ERROR_NAME for a code that is no sampler)
 * the Python API's message goes to message[message_size]. */
PYOA_HOST_FN int pyoa_sampler_offset(pyoa_u32 sampler_code, const char *offset, pyoa_u32 *code, char *message,
                                     size_t message_size)
{
    pyoa_text t = pyoa_text_start(message, message_size);
    pyoa_u32 k;
    if (pyoa_sampler_name(sampler_code) == NULL) {
        pyoa_text_str(&t, "unknown sampler code ");
        pyoa_text_u32(&t, sampler_code);
        return PYOA_ERROR_NAME;
    }
    if (pyoa_counts_family(sampler_code) != 0) {
        if (offset == NULL) {
            *code = PYOA_OFFSET_NONE;
            return PYOA_OK;
        }
        pyoa_text_str(&t, "offset applies to the orthogonal-array samplers only; ");
        pyoa_text_str(&t, pyoa_sampler_name(sampler_code));
        pyoa_text_str(&t, " has none (got offset=");
        pyoa_text_repr(&t, offset);
        pyoa_text_char(&t, ')');
        return PYOA_ERROR_OFFSET;
    }
    if (pyoa_offset_code(offset, code) == PYOA_OK)
        return PYOA_OK;
    pyoa_text_str(&t, "unknown offset ");
    pyoa_text_repr(&t, offset);
    pyoa_text_str(&t, "; valid: ");
    for (k = 0u; k < 4u; ++k) {
        pyoa_text_str(&t, k ? ", " : "");
        pyoa_text_str(&t, pyoa_offset_name(k));
    }
    pyoa_text_str(&t, " (default 'cmj')");
    return PYOA_ERROR_OFFSET;
}

/* ------------------------------------------------------- zfaure's shape */

/* reference.zfaure.check_shape's last check, for a valid count N and base
 * b: 1 if the padded grid's b^(2k) pixels times N samples fit the 64-bit
 * index, else 0 with its message. */
PYOA_HOST_FN int pyoa_counts_zfaure_shape(pyoa_text *t, pyoa_u32 N, pyoa_u32 b, pyoa_u32 width, pyoa_u32 height)
{
    pyoa_u32 k = pyoa_counts_grid_digits(b, width, height);
    if (pyoa_counts_zfaure_fits(N, b, k))
        return 1;
    pyoa_text_str(t, "zfaure: a ");
    pyoa_text_u32(t, width);
    pyoa_text_str(t, " x ");
    pyoa_text_u32(t, height);
    pyoa_text_str(t, " image in base ");
    pyoa_text_u32(t, b);
    pyoa_text_str(t, " pads to a ");
    pyoa_text_u32(t, b);
    pyoa_text_char(t, '^');
    pyoa_text_u32(t, k);
    pyoa_text_str(t, " x ");
    pyoa_text_u32(t, b);
    pyoa_text_char(t, '^');
    pyoa_text_u32(t, k);
    pyoa_text_str(t, " grid, and ");
    pyoa_text_u32(t, b);
    pyoa_text_char(t, '^');
    pyoa_text_u32(t, 2u * k);
    pyoa_text_str(t, " pixels x ");
    pyoa_text_u32(t, N);
    pyoa_text_str(t, " samples pass the 64-bit index (at most 2^64); use a smaller base, image or count");
    return 0;
}

/* ZFaure.with_base's message for a prime `base` other than the count's
 * own, N = b^m: the first six counts of that base (b^2, b^3, ...). */
PYOA_HOST_FN void pyoa_counts_zfaure_base_error(pyoa_text *t, pyoa_u32 N, pyoa_u32 b, pyoa_u32 m, pyoa_u32 base)
{
    pyoa_u64 power = (pyoa_u64)base * base;
    pyoa_u32 shown = 0u;
    pyoa_text_str(t, "zfaure: ");
    pyoa_text_u32(t, N);
    pyoa_text_str(t, " samples are ");
    pyoa_text_u32(t, b);
    pyoa_text_char(t, '^');
    pyoa_text_u32(t, m);
    pyoa_text_str(t, ", base ");
    pyoa_text_u32(t, b);
    pyoa_text_str(t, "; base ");
    pyoa_text_u32(t, base);
    pyoa_text_str(t, " takes ");
    for (; power <= PYOA_MAX_SPP; power *= base) {
        if (shown == 6u) {
            pyoa_text_str(t, ", ...");
            break;
        }
        pyoa_text_str(t, shown++ ? ", " : "");
        pyoa_text_u32(t, (pyoa_u32)power);
    }
    pyoa_text_str(t, " (the count fixes the base: give one of these counts, or no base)");
}

/* ---------------------------------------------------------------- solving */

/* The steps of pyoa.Sampler.__init__ after the name, in its order: spp in
 * [1, 2^24]; dims in [1, 2^20] (0: not given); the offset (when `check_offset`);
 * Construction.resolve (the strength, a comparison sampler's dims, the
 * count); with_resolution; with_base. */
PYOA_HOST_FN int pyoa_counts_resolve(pyoa_u32 code, pyoa_u32 spp, pyoa_u32 strength, pyoa_u32 dims, int check_offset,
                                     const char *offset, pyoa_u32 *offset_code, const float *jitter, pyoa_u32 base,
                                     pyoa_u32 width, pyoa_u32 height, pyoa_params *out, char *message,
                                     size_t message_size)
{
    pyoa_text t = pyoa_text_start(message, message_size);
    const char *name = pyoa_sampler_name(code);
    pyoa_params p;
    int rc;
    if (name == NULL) {
        pyoa_text_str(&t, "unknown sampler code ");
        pyoa_text_u32(&t, code);
        return PYOA_ERROR_NAME;
    }
    if (spp < 1u || spp > PYOA_MAX_SPP) {
        /* the Python API's message names no count; this one adds the nearest */
        pyoa_text_str(&t, "spp must be in [1, 16777216], got ");
        pyoa_text_u32(&t, spp);
        if (dims <= PYOA_MAX_DIMS && pyoa_counts_solve(code, 1u, dims, strength, &p, NULL) <= 0)
            pyoa_counts_nearest_text(&t, code, spp, dims, strength);
        return PYOA_ERROR_SPP;
    }
    if (dims > PYOA_MAX_DIMS) {
        pyoa_text_str(&t, "dims must be in [1, 1048576], got ");
        pyoa_text_u32(&t, dims);
        return PYOA_ERROR_DIMS;
    }
    if (check_offset) {
        rc = pyoa_sampler_offset(code, offset, offset_code, message, message_size);
        if (rc != PYOA_OK)
            return rc;
    }
    /* samplers._jitter: in [0, 1] (NaN fails too); other than 1 only for
     * the OA samplers, jittered2d and cmj2d */
    if (jitter != NULL) {
        char shown[32];
        snprintf(shown, sizeof shown, "%.9g", (double)*jitter);
        if (!(*jitter >= 0.0f && *jitter <= 1.0f)) {
            pyoa_text_str(&t, "jitter must be in [0, 1] (1 = full jitter, 0 = cell centres), got ");
            pyoa_text_str(&t, shown);
            return PYOA_ERROR_JITTER;
        }
        if (*jitter != 1.0f && pyoa_counts_family(code) != 0 && code != PYOA_SAMPLER_JITTERED2D &&
            code != PYOA_SAMPLER_CMJ2D) {
            pyoa_text_str(&t, name);
            pyoa_text_str(&t, " has no jitter amount (got jitter=");
            pyoa_text_str(&t, shown);
            pyoa_text_str(&t, "); it applies to the orthogonal-array samplers, jittered2d and cmj2d");
            return PYOA_ERROR_JITTER;
        }
    }
    rc = pyoa_counts_solve(code, spp, dims, strength, &p, &t);
    if (rc > 0)
        return rc;
    if (rc < 0) { /* Construction.resolve's message */
        pyoa_text_str(&t, name);
        pyoa_text_str(&t, ": ");
        pyoa_counts_invalid(&t, code, spp, dims, strength);
        pyoa_counts_nearest_text(&t, code, spp, dims, strength);
        pyoa_counts_elsewhere(&t, code, spp, dims);
        return PYOA_ERROR_SPP;
    }
    /* with_resolution: zsobol and zfaure need width x height, each in
     * [1, 2^16]; the others refuse one (width = height = 0 is none) */
    if (!pyoa_needs_resolution(code) && (width != 0u || height != 0u)) {
        pyoa_text_str(&t, name);
        pyoa_text_str(&t, " takes no resolution (got resolution=(");
        pyoa_text_u32(&t, width);
        pyoa_text_str(&t, ", ");
        pyoa_text_u32(&t, height);
        pyoa_text_str(&t, ")); only zsobol, zfaure depend on where a pixel lies in the image");
        return PYOA_ERROR_RESOLUTION;
    }
    if (pyoa_needs_resolution(code)) {
        int bad_width = width < 1u || width > PYOA_COUNTS_MAX_RESOLUTION;
        if (width == 0u && height == 0u) {
            pyoa_text_str(&t, name);
            pyoa_text_str(&t, " needs the image: resolution=(width, height), each in [1, 65536] (");
            pyoa_text_str(&t, code == PYOA_SAMPLER_ZSOBOL ? "its Z-order curve spans the image"
                                                          : "its Morton order spans the image");
            pyoa_text_str(&t, "; pixels are numbered row-major, y * width + x)");
            return PYOA_ERROR_RESOLUTION;
        }
        if (bad_width || height < 1u || height > PYOA_COUNTS_MAX_RESOLUTION) {
            pyoa_text_str(&t, bad_width ? "resolution width" : "resolution height");
            pyoa_text_str(&t, " must be in [1, 65536], got ");
            pyoa_text_u32(&t, bad_width ? width : height);
            return PYOA_ERROR_RESOLUTION;
        }
        if (code == PYOA_SAMPLER_ZFAURE && !pyoa_counts_zfaure_shape(&t, p.M, p.s, width, height))
            return PYOA_ERROR_RESOLUTION;
        p.width = width;
        p.height = height;
    }
    /* with_base: faure's and zfaure's prime base; the others refuse one (0 is none) */
    if (base != 0u && pyoa_counts_family(code) != 2) {
        pyoa_text_str(&t, name);
        pyoa_text_str(&t, " takes no base (got base=");
        pyoa_text_u32(&t, base);
        pyoa_text_str(&t, "); only faure, zfaure have a digit base");
        return PYOA_ERROR_BASE;
    }
    if (base != 0u) {
        if (base > PYOA_COUNTS_MAX_BASE || !pyoa_is_prime(base)) {
            /* the two primes closest to base (a tie to the smaller), in increasing order */
            pyoa_u32 below[2] = {0u, 0u}, above[2] = {0u, 0u}, nb = 0u, na = 0u, x, pick[2], k;
            for (x = base > PYOA_COUNTS_MAX_BASE ? PYOA_COUNTS_MAX_BASE : base - 1u; x >= 2u && nb < 2u; --x)
                if (pyoa_is_prime(x))
                    below[nb++] = x;
            for (x = base + 1u; base < PYOA_COUNTS_MAX_BASE && x <= PYOA_COUNTS_MAX_BASE && na < 2u; ++x)
                if (pyoa_is_prime(x))
                    above[na++] = x;
            for (k = 0u, nb = 0u, na = 0u; k < 2u; ++k) { /* merge by distance, ties to the smaller */
                int take_below = nb < 2u && below[nb] != 0u
                                 && (na >= 2u || above[na] == 0u || base - below[nb] <= above[na] - base);
                pick[k] = take_below ? below[nb++] : above[na++];
            }
            /* Faure.with_base's message, which zfaure inherits */
            pyoa_text_str(&t, name);
            pyoa_text_str(&t, ": base must be a prime in [2, 4093], got ");
            pyoa_text_u32(&t, base);
            pyoa_text_str(&t, "; nearest: ");
            pyoa_text_u32(&t, pick[0] < pick[1] ? pick[0] : pick[1]);
            pyoa_text_str(&t, ", ");
            pyoa_text_u32(&t, pick[0] < pick[1] ? pick[1] : pick[0]);
            return PYOA_ERROR_BASE;
        }
        if (code == PYOA_SAMPLER_ZFAURE && base != p.s) { /* the count fixes the base */
            pyoa_counts_zfaure_base_error(&t, p.M, p.s, p.strength, base);
            return PYOA_ERROR_BASE;
        }
        p.s = base;
        p.block_dims = base;
        p.strength = pyoa_counts_levels(base, p.M);
    }
    *out = p;
    return PYOA_OK;
}

/* Resolve sampler `code` (PYOA_SAMPLER_<NAME>) at `spp` samples per pixel
 * into *out, as pyoa.Sampler does (pyoa.catalogue's resolve):
 *   strength  bush's and cmjnd's t (0: the default, the largest t <= dims
 *             with spp = s^t; bose and the index-2 arrays accept only 2,
 *             the comparison samplers none);
 *   dims      the number of dimensions (0: unknown, as valid_spp's
 *             dims=None: bush then tries t up to 8, cmjnd up to 24, faure's
 *             default base ignores dims, jittered2d's last dimension is
 *             never a lone one, and halton's and sobol's limits are not
 *             checked); at most 2^20;
 *   width, height  zsobol's and zfaure's image, each in [1, 65536]; 0, 0
 *             for every other sampler (which refuses an image, as the Python
 *             API does).
 * Returns PYOA_OK, or the error code with the Python API's message in
 * message[message_size] (NULL allowed; snprintf's truncation): an invalid
 * count gives "bose: 120 is not s^2 ...; nearest: 81 (s=9), 121 (s=11); 120
 * is valid for ..." with the same counts as Python's ValueError; a count
 * outside [1, 2^24] gives the Sampler's "spp must be in [1, 16777216], got
 * 0" followed by "; nearest: ..." (Python's names no counts there). *out is
 * written only on success. */
PYOA_HOST_FN int pyoa_solve(pyoa_u32 code, pyoa_u32 spp, pyoa_u32 strength, pyoa_u32 dims, pyoa_u32 width,
                            pyoa_u32 height, pyoa_params *out, char *message, size_t message_size)
{
    return pyoa_counts_resolve(code, spp, strength, dims, 0, NULL, NULL, NULL, 0u, width, height, out, message,
                               message_size);
}

/* pyoa_solve with faure's or zfaure's `base` (pyoa.sampler(..., base=)): 0
 * is the default (faure: progressive.default_base, the largest prime b with
 * b^2 <= spp, or the smallest prime >= dims when that is no larger; zfaure:
 * the count's, spp = b^m); else a prime in [2, 4093] (zfaure: the count's
 * own), out->s = out->block_dims = base and out->strength the largest m
 * with base^m <= spp. Any other sampler refuses a base (PYOA_ERROR_BASE),
 * as the Python API does. */
PYOA_HOST_FN int pyoa_solve_base(pyoa_u32 code, pyoa_u32 spp, pyoa_u32 strength, pyoa_u32 dims, pyoa_u32 base,
                                 pyoa_u32 width, pyoa_u32 height, pyoa_params *out, char *message, size_t message_size)
{
    return pyoa_counts_resolve(code, spp, strength, dims, 0, NULL, NULL, NULL, base, width, height, out, message,
                               message_size);
}

/* Everything pyoa.Sampler(name, spp=, dims=, offset=, jitter=, strength=,
 * resolution=, base=) checks, in its order, with its messages: the name
 * (catalogue name or alias, any case), spp, dims (0: unknown, see
 * pyoa_solve), the offset (pyoa_sampler_offset: NULL the default; the
 * comparison samplers, faure and zfaure refuse one), the jitter amount (1: the
 * default; PYOA_ERROR_JITTER), the strength and count, the
 * resolution, the base. On success *out and *offset_code (which may be
 * NULL) are written: the offset's PYOA_OFFSET_<NAME>, PYOA_OFFSET_NONE for
 * the samplers without one. */
PYOA_HOST_FN int pyoa_resolve(const char *name, pyoa_u32 spp, pyoa_u32 strength, pyoa_u32 dims, const char *offset,
                              float jitter, pyoa_u32 base, pyoa_u32 width, pyoa_u32 height, pyoa_params *out,
                              pyoa_u32 *offset_code, char *message, size_t message_size)
{
    pyoa_u32 code = 0u, off = 0u;
    pyoa_params p;
    int rc;
    if (pyoa_lookup(name, &code) != PYOA_OK) {
        pyoa_name_error(name, message, message_size);
        return PYOA_ERROR_NAME;
    }
    rc = pyoa_counts_resolve(code, spp, strength, dims, 1, offset, &off, &jitter, base, width, height, &p, message,
                             message_size);
    if (rc == PYOA_OK) {
        *out = p;
        if (offset_code != NULL)
            *offset_code = off;
    }
    return rc;
}

/* ------------------------------------------------------- shape arguments */

/* reference.zsobol.resolution_log2: log2 of the smallest power of two >=
 * max(width, height). */
PYOA_HOST_FN pyoa_u32 pyoa_counts_resolution_log2(pyoa_u32 width, pyoa_u32 height)
{
    pyoa_u32 m = width > height ? width : height;
    return m == 0u ? 0u : pyoa_counts_bit_length(m - 1u);
}

/* reference.faure.index_digits: how many base-b digits the indices [0, n)
 * have (at least 1). */
PYOA_HOST_FN pyoa_u32 pyoa_counts_index_digits(pyoa_u32 b, pyoa_u32 n)
{
    pyoa_u32 digits = 1u;
    pyoa_u64 power = b;
    while (power < n) {
        power *= b;
        digits++;
    }
    return digits;
}

/* The entry's shape_args(params), zero-padded to three (what the OpenCL
 * backend passes its kernels as a, b, c, pyoa/_opencl/backend.py; zfaure's
 * four packed into three):
 *   bose, addelman-kempthorne, bose-bush   (s)
 *   bush, cmjnd                            (s, t)
 *   random, halton, sobol                  ()
 *   jittered2d                             (m, dims): dims decides whether
 *                                          the last dimension is a lone one
 *   cmj2d                                  (m, n): the m x n grid
 *   sobol02, pmj02                         (log2 spp)
 *   zsobol                                 (log2 spp, log2 of the image's
 *                                          power-of-two side, width)
 *   faure                                  (b, index_digits(b, spp)): the
 *                                          base-b digits of the largest
 *                                          index spp - 1, so valid for every
 *                                          sample of the sampler (any n with
 *                                          b^n > i gives sample i's value)
 *   zfaure                                 (spp, b | k << 16, width): its
 *                                          four (spp, b, k, width), k the
 *                                          digits of the image's padded
 *                                          b^k x b^k grid, as the three words
 *                                          of its launch (ZFaure.launch; b <
 *                                          2^12, k <= 16)
 * The OA samplers' kernel also takes block_dims, s * M, M and the offset
 * (generate.cl), which pyoa_params holds. */
PYOA_HOST_FN void pyoa_shape_args(const pyoa_params *p, pyoa_u32 *a, pyoa_u32 *b, pyoa_u32 *c)
{
    *a = *b = *c = 0u;
    switch (p->code) {
    case PYOA_SAMPLER_BOSE: case PYOA_SAMPLER_ADDELMAN_KEMPTHORNE: case PYOA_SAMPLER_BOSE_BUSH: *a = p->s; break;
    case PYOA_SAMPLER_BUSH: case PYOA_SAMPLER_CMJND: *a = p->s; *b = p->strength; break;
    case PYOA_SAMPLER_JITTERED2D: *a = p->s; *b = p->dims; break;
    case PYOA_SAMPLER_CMJ2D: *a = p->s; *b = p->M; break;
    case PYOA_SAMPLER_SOBOL02: case PYOA_SAMPLER_PMJ02: *a = pyoa_counts_bit_length(p->M) - 1u; break;
    case PYOA_SAMPLER_ZSOBOL:
        *a = pyoa_counts_bit_length(p->M) - 1u;
        *b = pyoa_counts_resolution_log2(p->width, p->height);
        *c = p->width;
        break;
    case PYOA_SAMPLER_FAURE: *a = p->s; *b = pyoa_counts_index_digits(p->s, p->M); break;
    case PYOA_SAMPLER_ZFAURE:
        *a = p->M;
        *b = p->s | pyoa_counts_grid_digits(p->s, p->width, p->height) << 16;
        *c = p->width;
        break;
    default: break;
    }
}

#endif /* !__OPENCL_VERSION__ */
#endif /* PYOA_COUNTS_H */
