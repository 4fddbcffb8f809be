/* Galois-field arithmetic (mirrors pyoa/gf.py): mod q for prime q, else the
 * lookup tables built once in Python, passed as one buffer `gf` holding the
 * q*q addition table followed by the q*q multiplication table (uint16). For
 * prime q, `gf` is a 1-element placeholder and tabled == 0; the index is
 * clamped to 0 then, so no lane ever reads past the placeholder. */

uint gf_add(uint a, uint b, uint q, __global const ushort *gf, uint tabled)
{
    uint k = tabled ? a * q + b : 0u;
    return tabled ? (uint)gf[k] : (a + b) % q;
}

uint gf_mul(uint a, uint b, uint q, __global const ushort *gf, uint tabled)
{
    uint k = tabled ? q * q + a * q + b : 0u;
    return tabled ? (uint)gf[k] : (a * b) % q;
}
