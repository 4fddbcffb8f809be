/* Owen-scrambled Faure (0,s)-sequences in a prime base b: the progressive
 * orthogonal arrays of pyoa/reference/faure.py (the mathematics, its
 * references and the float rule are there; this is the same computation,
 * operation for operation). */

/* PYOA_FAURE_KEY and PYOA_FAURE_DIGIT_KEY come from pyoa/keys.h, generated from
 * pyoa/reference/faure.py, their only definition. */

/* Most digits K (b^K >= 2^24): 24, in base 2. */
#define FAURE_MAX_DIGITS 24

/* The fewest base-b digits K with b^K >= 2^24. */
static inline uint faure_digits(uint b)
{
    uint K = 0u;
    for (ulong power = 1ul; power < 0x1000000ul; power *= b)
        K++;
    return K;
}

/* Sample i, dimension j in base b, with the Taylor shift over the n lowest
 * digits of i (i < b^n; the host passes the digits of its largest index, the
 * same for every work-item, so the loops below are uniform). */
float sample_faure(uint i, uint j, uint b, uint n, uint p)
{
    uint col = j % b, block = j / b;
    uint P = pyoa_block_seed(p, block);
    uint q = derived_seed(P, col, PYOA_FAURE_KEY);
    uint a[FAURE_MAX_DIGITS];
    if (block)  /* a copy: all K digits of its nested-scrambled index */
        n = faure_digits(b);
    uint rest = i;
    for (uint r = 0u; r < n; r++) {
        a[r] = rest % b;
        rest /= b;
    }
    if (block) {
        /* every copy past the first reads the sequence in its own nested
         * order: digit r permuted by a hash of the digits above it */
        uint s = pyoa_hash_pair(P, b, PYOA_FAURE_INDEX_KEY), high = 0u, power = 1u;
        for (uint r = n; r-- > 0u;) {
            uint d = a[r];
            a[r] = pyoa_permute(d, b, pyoa_hash_pair(s, power + high, PYOA_FAURE_DIGIT_KEY));
            high = high * b + d;
            power *= b;
        }
    }
    /* a becomes the coefficients of A(x + col) mod b: y_k = a[k]
     * (repeated synthetic division; products stay below b^2 <= 2^24) */
    for (uint k = 0u; k + 1u < n; k++)
        for (uint r = n - 1u; r-- > k;)
            a[r] = (a[r] + col * a[r + 1u]) % b;
    /* nested scrambling of the K output digits, b^K >= 2^24 */
    ulong numer = 0ul, power = 1ul;  /* power = b^k */
    uint prefix = 0u;                /* (y_0 ... y_{k-1}) in base b */
    for (uint k = 0u; power < 0x1000000ul; k++) {
        uint y = k < n ? a[k] : 0u;
        uint yy = q ? pyoa_permute(y, b, pyoa_hash_pair(q, (uint)power + prefix, PYOA_FAURE_DIGIT_KEY)) : y;
        numer = numer * b + yy;
        prefix = prefix * b + y;
        power *= b;
    }
    /* the cell clamp: keep the 24-bit value in its cell of b^-L, b^L <= 2^24
     * (L = K for b = 2, where b^K = 2^24, else K - 1) */
    ulong fine = power == 0x1000000ul ? power : power / b;
    ulong x24 = (numer << 24) / power;
    ulong lo = (((numer / (power / fine)) << 24) + fine - 1ul) / fine;
    return convert_float((uint)max(x24, lo)) * 0x1.0p-24f;
}
