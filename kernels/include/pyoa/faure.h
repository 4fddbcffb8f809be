/* pyoa/faure.h: Owen-scrambled Faure (0,s)-sequences in a prime base b, the
 * progressive orthogonal arrays of docs/spec.md section 5.11
 * (pyoa/reference/faure.py holds the mathematics, its references and the
 * float rule; this is the same computation, operation for operation). */
#ifndef PYOA_FAURE_H
#define PYOA_FAURE_H

#include "baselines.h"
#include "config.h"
#include "hashes.h"
#include "keys.h"

/* Most digits K (b^K >= 2^24): 24, in base 2. */
#define PYOA_FAURE_MAX_DIGITS 24

/* The fewest base-b digits K with b^K >= 2^24. */
PYOA_FN pyoa_u32 pyoa_faure_digits(pyoa_u32 b)
{
    pyoa_u32 K = 0u;
    for (pyoa_u64 power = 1u; power < 0x1000000u; power *= b)
        K++;
    return K;
}

/* Coordinate col of the index whose base-b digits are a[0 .. n-1] (least
 * significant first, after any index scramble), Owen-scrambled with seed q
 * (0: unscrambled): the Taylor shift, the nested output scramble and the
 * float rule, shared by faure and zfaure (pyoa/zfaure.h) as
 * reference.faure.digits_value is. a is overwritten. */
PYOA_FN float pyoa_faure_digits_value(pyoa_u32 *a, pyoa_u32 n, pyoa_u32 b, pyoa_u32 col, pyoa_u32 q)
{
    pyoa_u32 prefix = 0u;
    pyoa_u64 numer = 0u, power = 1u, fine, x24, lo;
    /* a becomes the coefficients of A(x + col) mod b: y_k = a[k]
     * (repeated synthetic division; products stay below b^2 <= 2^24).
     * Step k fixes y_k, and only y_0 .. y_(K-1) are read: the steps stop
     * at k = K (b^k >= 2^24), which only zfaure's longer indices reach */
    for (pyoa_u32 k = 0u; k + 1u < n && power < 0x1000000u; k++, power *= b)
        for (pyoa_u32 r = n - 1u; r-- > k;)
            a[r] = (a[r] + col * a[r + 1u]) % b;
    /* nested scrambling of the K output digits, b^K >= 2^24; power = b^k,
     * prefix = (y_0 ... y_{k-1}) in base b */
    power = 1u;
    for (pyoa_u32 k = 0u; power < 0x1000000u; k++) {
        pyoa_u32 y = k < n ? a[k] : 0u;
        pyoa_u32 yy = q ? pyoa_permute(y, b, pyoa_hash_pair(q, (pyoa_u32)power + prefix, PYOA_FAURE_DIGIT_KEY)) : y;
        numer = numer * b + yy;
        prefix = prefix * b + y;
        power *= b;
    }
    /* the cell clamp: keep the 24-bit value in its cell of b^-L, b^L <= 2^24
     * (L = K for b = 2, where b^K = 2^24, else K - 1) */
    fine = power == 0x1000000u ? power : power / b;
    x24 = (numer << 24) / power;
    lo = (((numer / (power / fine)) << 24) + fine - 1u) / fine;
    return PYOA_MUL(PYOA_U32_TO_F32((pyoa_u32)PYOA_MAX(x24, lo)), PYOA_2POW_M24);
}

/* Sample i, dimension j in base b, of the sequence with seed p, with the
 * Taylor shift over the n lowest digits of i: any n with i < b^n and
 * n <= pyoa_faure_digits(b) gives the same value (the digits above i's are
 * 0 and stay 0); a bulk generator passes the digits of its largest index,
 * the same for every value, so that the loops below are uniform. */
PYOA_FN float pyoa_sample_faure(pyoa_u32 i, pyoa_u32 j, pyoa_u32 b, pyoa_u32 n, pyoa_u32 p)
{
    pyoa_u32 col = j % b, block = j / b;
    pyoa_u32 P = pyoa_block_seed(p, block);
    pyoa_u32 a[PYOA_FAURE_MAX_DIGITS];
    pyoa_u32 rest = i;
    if (block) /* a copy: all K digits of its nested-scrambled index */
        n = pyoa_faure_digits(b);
    for (pyoa_u32 r = 0u; r < n; r++) {
        a[r] = rest % b;
        rest /= b;
    }
    if (block) {
        /* every copy past the first reads the sequence in its own nested
         * order: digit r permuted by a hash of the digits above it */
        pyoa_u32 s = pyoa_hash_pair(P, b, PYOA_FAURE_INDEX_KEY), high = 0u, pw = 1u;
        for (pyoa_u32 r = n; r-- > 0u;) {
            pyoa_u32 d = a[r];
            a[r] = pyoa_permute(d, b, pyoa_hash_pair(s, pw + high, PYOA_FAURE_DIGIT_KEY));
            high = high * b + d;
            pw *= b;
        }
    }
    return pyoa_faure_digits_value(a, n, b, col, pyoa_derived_seed(P, col, PYOA_FAURE_KEY));
}

#endif /* PYOA_FAURE_H */
