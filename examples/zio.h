/* zio.h - the byte-level helpers the examples' file codecs share: Adler-32, zlib streams
 * (RFC 1950) holding deflate data (RFC 1951) both ways, and the streaming atomic file
 * replacement of the raster writers (whole buffers go through the library's hfvis_write_file;
 * CRC-32 is the library's hfvis_crc32). Header-only, every function static inline, pure C99,
 * prints nothing. Used by png_write.h (Adler-32) and raster_io.h (inflate for DEFLATE TIFFs,
 * deflate for the TIFF writer, atomic files).
 *
 * Contents
 *   1. checksums        ex_adler32
 *   2. inflate          ex_inflate: a zlib or raw deflate stream into a buffer of known size
 *                       (codes of up to 9 bits by table, longer ones bit by bit)
 *   3. deflate          ex_deflate_bound, ex_deflate_zlib: LZ77 (hash chains) + fixed Huffman
 *                       (codes from tables made per stream), a stored block instead when that
 *                       is shorter; reentrant (the TIFF writer compresses tiles concurrently)
 *   4. atomic files     ex_atomic_open, ex_atomic_close; ex_publish_* (a file and its
 *                       sidecars replaced together)
 */
#ifndef HFVIS_EXAMPLES_ZIO_H
#define HFVIS_EXAMPLES_ZIO_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hfvis.h"

/* ------------------------------------------------------------------------------------------ */
/* 1. checksums                                                                               */
/* ------------------------------------------------------------------------------------------ */

/* Adler-32 of RFC 1950 §8.2 over n bytes, continuing adler (start from 1):
 * ex_adler32(1, "Wikipedia", 9) = 0x11E60398. Reduces mod 65521 every 5552 bytes, the
 * longest run whose sums cannot overflow 32 bits (zlib's NMAX). */
static inline uint32_t ex_adler32(uint32_t adler, const unsigned char *p, size_t n)
{
    uint32_t a = adler & 0xffffu, b = adler >> 16;
    while (n > 0) {
        size_t k = n < 5552u ? n : 5552u, i;
        for (i = 0; i < k; i++) {
            a += p[i];
            b += a;
        }
        a %= 65521u;
        b %= 65521u;
        p += k;
        n -= k;
    }
    return (b << 16) | a;
}

/* ------------------------------------------------------------------------------------------ */
/* 2. inflate                                                                                 */
/* ------------------------------------------------------------------------------------------ */

/* Results of ex_inflate. */
enum {
    EX_Z_OK = 0,
    EX_Z_TRUNCATED = 1, /* the input ended inside the stream */
    EX_Z_BAD = 2,       /* an invalid header, block type, code set, code or distance */
    EX_Z_OVERFLOW = 3,  /* the stream holds more bytes than the output's capacity */
    EX_Z_CHECK = 4      /* the Adler-32 check value differs */
};

/* Longest Huffman code of deflate (RFC 1951 §3.2.7). */
#define EX_Z_MAXBITS 15

typedef struct {
    const unsigned char *in;
    size_t in_len, in_pos;
    uint32_t bits;
    int nbits;
    unsigned char *out;
    size_t out_len, out_pos;
    int truncated;
} ex_z_state;

/* A canonical Huffman code as counts per length and symbols in code order (Mark Adler's puff),
 * and a table of the codes of at most EX_Z_FAST_BITS bits by the next EX_Z_FAST_BITS bits of the
 * stream: symbol << 4 | length, or -1 (a longer code, or none: the canonical walk decides). */
#define EX_Z_FAST_BITS 9
typedef struct {
    short count[EX_Z_MAXBITS + 1];
    short symbol[288];
    short fast[1 << EX_Z_FAST_BITS];
} ex_z_huff;

static inline int ex_z_bits(ex_z_state *s, int need)
{
    uint32_t v = s->bits;
    while (s->nbits < need) {
        if (s->in_pos == s->in_len) {
            s->truncated = 1;
            return 0;
        }
        v |= (uint32_t)s->in[s->in_pos++] << s->nbits;
        s->nbits += 8;
    }
    s->bits = v >> need;
    s->nbits -= need;
    return (int)(v & ((1u << need) - 1u));
}

/* Back to the byte boundary: the bits of the partial byte dropped, whole bytes the decoder took
 * ahead (ex_z_decode's look-ahead) returned to the input. */
static inline void ex_z_align(ex_z_state *s)
{
    s->in_pos -= (size_t)(s->nbits >> 3);
    s->bits = 0;
    s->nbits = 0;
}

/* Decode one symbol: by the table when EX_Z_FAST_BITS bits are at hand and the code is that
 * short, else the code bit by bit (codes are stored most significant bit first). */
static inline int ex_z_decode(ex_z_state *s, const ex_z_huff *h)
{
    int code = 0, first = 0, index = 0, len;
    while (s->nbits < EX_Z_FAST_BITS && s->in_pos < s->in_len) {
        s->bits |= (uint32_t)s->in[s->in_pos++] << s->nbits;
        s->nbits += 8;
    }
    if (s->nbits >= EX_Z_FAST_BITS) {
        int e = h->fast[s->bits & ((1u << EX_Z_FAST_BITS) - 1u)];
        if (e >= 0) {
            s->bits >>= e & 15;
            s->nbits -= e & 15;
            return e >> 4;
        }
    }
    for (len = 1; len <= EX_Z_MAXBITS; len++) {
        int count;
        code |= ex_z_bits(s, 1);
        if (s->truncated) return -1;
        count = h->count[len];
        if (code - count < first) return h->symbol[index + (code - first)];
        index += count;
        first += count;
        first <<= 1;
        code <<= 1;
    }
    return -2; /* ran out of codes */
}

/* The n low bits of code in reverse order (Huffman codes travel most significant bit first,
 * RFC 1951 §3.1.1; the bit buffers here fill from the least significant end). */
static inline uint32_t ex_z_reverse(uint32_t code, int n)
{
    uint32_t r = 0;
    int i;
    for (i = 0; i < n; i++) r |= ((code >> i) & 1u) << (n - 1 - i);
    return r;
}

/* Build h from n code lengths; 0 when complete or (as RFC 1951 allows for one distance code)
 * incomplete, -1 when over-subscribed. */
static inline int ex_z_build(ex_z_huff *h, const short *length, int n)
{
    short offs[EX_Z_MAXBITS + 1];
    int symbol, len, left;
    for (symbol = 0; symbol < (1 << EX_Z_FAST_BITS); symbol++) h->fast[symbol] = -1;
    for (len = 0; len <= EX_Z_MAXBITS; len++) h->count[len] = 0;
    for (symbol = 0; symbol < n; symbol++) h->count[length[symbol]]++;
    if (h->count[0] == n) return 0;
    left = 1;
    for (len = 1; len <= EX_Z_MAXBITS; len++) {
        left <<= 1;
        left -= h->count[len];
        if (left < 0) return -1;
    }
    offs[1] = 0;
    for (len = 1; len < EX_Z_MAXBITS; len++) offs[len + 1] = (short)(offs[len] + h->count[len]);
    for (symbol = 0; symbol < n; symbol++)
        if (length[symbol] != 0) h->symbol[offs[length[symbol]]++] = (short)symbol;
    /* the short codes' table (left >= 0 here: complete or incomplete, never over-subscribed, so
     * every code of length len is below 2^len) */
    {
        int index = 0, code = 0, k, f;
        for (len = 1; len <= EX_Z_FAST_BITS; len++) {
            for (k = 0; k < h->count[len]; k++, code++)
                for (f = (int)ex_z_reverse((uint32_t)code, len); f < (1 << EX_Z_FAST_BITS); f += 1 << len)
                    h->fast[f] = (short)(h->symbol[index + k] << 4 | len);
            index += h->count[len];
            code <<= 1;
        }
    }
    return left;
}

static const short ex_z_len_base[29] = { 3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31,
                                         35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258 };
static const short ex_z_len_extra[29] = { 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2,
                                          3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0 };
static const short ex_z_dist_base[30] = { 1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193,
                                          257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145,
                                          8193, 12289, 16385, 24577 };
static const short ex_z_dist_extra[30] = { 0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6,
                                           7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13 };

/* Literals and matches of one compressed block until its end-of-block code. */
static inline int ex_z_codes(ex_z_state *s, const ex_z_huff *lit, const ex_z_huff *dist)
{
    for (;;) {
        int sym = ex_z_decode(s, lit);
        if (s->truncated) return EX_Z_TRUNCATED;
        if (sym < 0) return EX_Z_BAD;
        if (sym < 256) {
            if (s->out_pos == s->out_len) return EX_Z_OVERFLOW;
            s->out[s->out_pos++] = (unsigned char)sym;
        } else if (sym == 256) {
            return EX_Z_OK;
        } else {
            size_t len, d;
            int e;
            sym -= 257;
            if (sym >= 29) return EX_Z_BAD;
            len = (size_t)ex_z_len_base[sym] + (size_t)ex_z_bits(s, ex_z_len_extra[sym]);
            e = ex_z_decode(s, dist);
            if (s->truncated) return EX_Z_TRUNCATED;
            if (e < 0 || e >= 30) return EX_Z_BAD;
            d = (size_t)ex_z_dist_base[e] + (size_t)ex_z_bits(s, ex_z_dist_extra[e]);
            if (s->truncated) return EX_Z_TRUNCATED;
            if (d > s->out_pos) return EX_Z_BAD; /* before the start of the output */
            if (len > s->out_len - s->out_pos) return EX_Z_OVERFLOW;
            while (len--) {
                s->out[s->out_pos] = s->out[s->out_pos - d];
                s->out_pos++;
            }
        }
    }
}

static inline int ex_z_fixed(ex_z_state *s)
{
    ex_z_huff lit, dist;
    short len[288];
    int i;
    for (i = 0; i < 144; i++) len[i] = 8;
    for (; i < 256; i++) len[i] = 9;
    for (; i < 280; i++) len[i] = 7;
    for (; i < 288; i++) len[i] = 8;
    ex_z_build(&lit, len, 288);
    for (i = 0; i < 30; i++) len[i] = 5;
    ex_z_build(&dist, len, 30);
    return ex_z_codes(s, &lit, &dist);
}

static inline int ex_z_dynamic(ex_z_state *s)
{
    static const short order[19] = { 16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15 };
    short len[320];
    ex_z_huff lencode, lit, dist;
    int nlen, ndist, ncode, i, err;
    nlen = ex_z_bits(s, 5) + 257;
    ndist = ex_z_bits(s, 5) + 1;
    ncode = ex_z_bits(s, 4) + 4;
    if (s->truncated) return EX_Z_TRUNCATED;
    if (nlen > 286 || ndist > 30) return EX_Z_BAD;
    for (i = 0; i < 19; i++) len[order[i]] = (short)(i < ncode ? ex_z_bits(s, 3) : 0);
    if (s->truncated) return EX_Z_TRUNCATED;
    if (ex_z_build(&lencode, len, 19) != 0) return EX_Z_BAD; /* must be complete */
    i = 0;
    while (i < nlen + ndist) {
        int sym = ex_z_decode(s, &lencode), rep;
        short val = 0;
        if (s->truncated) return EX_Z_TRUNCATED;
        if (sym < 0) return EX_Z_BAD;
        if (sym < 16) {
            len[i++] = (short)sym;
            continue;
        }
        if (sym == 16) {
            if (i == 0) return EX_Z_BAD;
            val = len[i - 1];
            rep = 3 + ex_z_bits(s, 2);
        } else if (sym == 17) {
            rep = 3 + ex_z_bits(s, 3);
        } else {
            rep = 11 + ex_z_bits(s, 7);
        }
        if (s->truncated) return EX_Z_TRUNCATED;
        if (i + rep > nlen + ndist) return EX_Z_BAD;
        while (rep--) len[i++] = val;
    }
    if (len[256] == 0) return EX_Z_BAD; /* no end-of-block code */
    err = ex_z_build(&lit, len, nlen);
    if (err < 0 || (err > 0 && nlen - lit.count[0] != 1)) return EX_Z_BAD;
    err = ex_z_build(&dist, len + nlen, ndist);
    if (err < 0 || (err > 0 && ndist - dist.count[0] != 1)) return EX_Z_BAD;
    return ex_z_codes(s, &lit, &dist);
}

/* Inflate the zlib stream (zlib = 1; RFC 1950 header and Adler-32 checked) or raw deflate data
 * (zlib = 0) in[0..in_len) into out (capacity out_len); *produced = the bytes it held. Memory:
 * none beyond the caller's buffers (the tables live on the stack); time linear in the input plus
 * the output. Returns an EX_Z_* code. */
static inline int ex_inflate(const unsigned char *in, size_t in_len, unsigned char *out,
                             size_t out_len, int zlib, size_t *produced)
{
    ex_z_state s;
    int last = 0, rc = EX_Z_OK;
    *produced = 0;
    memset(&s, 0, sizeof s);
    s.in = in; s.in_len = in_len; s.out = out; s.out_len = out_len;
    if (zlib) {
        if (in_len < 2) return EX_Z_TRUNCATED;
        /* CM 8 (deflate), CINFO <= 7 (window <= 32 KiB), FCHECK, no preset dictionary */
        if ((in[0] & 15) != 8 || (in[0] >> 4) > 7 || ((unsigned)in[0] * 256u + in[1]) % 31u != 0 ||
            (in[1] & 0x20))
            return EX_Z_BAD;
        s.in_pos = 2;
    }
    while (!last) {
        int type;
        last = ex_z_bits(&s, 1);
        type = ex_z_bits(&s, 2);
        if (s.truncated) return EX_Z_TRUNCATED;
        if (type == 0) {
            size_t len;
            ex_z_align(&s); /* to a byte boundary */
            if (s.in_len - s.in_pos < 4) return EX_Z_TRUNCATED;
            len = (size_t)s.in[s.in_pos] | (size_t)s.in[s.in_pos + 1] << 8;
            if ((s.in[s.in_pos + 2] ^ s.in[s.in_pos]) != 0xff || (s.in[s.in_pos + 3] ^ s.in[s.in_pos + 1]) != 0xff)
                return EX_Z_BAD;
            s.in_pos += 4;
            if (s.in_len - s.in_pos < len) return EX_Z_TRUNCATED;
            if (s.out_len - s.out_pos < len) return EX_Z_OVERFLOW;
            memcpy(s.out + s.out_pos, s.in + s.in_pos, len);
            s.in_pos += len;
            s.out_pos += len;
        } else if (type == 1) {
            rc = ex_z_fixed(&s);
        } else if (type == 2) {
            rc = ex_z_dynamic(&s);
        } else {
            return EX_Z_BAD;
        }
        if (rc != EX_Z_OK) return rc;
    }
    *produced = s.out_pos;
    ex_z_align(&s); /* the check value starts at the next byte */
    if (zlib) {
        const unsigned char *c;
        uint32_t want;
        if (s.in_len - s.in_pos < 4) return EX_Z_TRUNCATED;
        c = s.in + s.in_pos;
        want = (uint32_t)c[0] << 24 | (uint32_t)c[1] << 16 | (uint32_t)c[2] << 8 | c[3];
        if (want != ex_adler32(1, out, s.out_pos)) return EX_Z_CHECK;
    }
    return EX_Z_OK;
}

/* A one-line reason for an EX_Z_* code. */
static inline const char *ex_inflate_string(int rc)
{
    switch (rc) {
    case EX_Z_OK: return "ok";
    case EX_Z_TRUNCATED: return "truncated deflate stream";
    case EX_Z_BAD: return "invalid deflate stream";
    case EX_Z_OVERFLOW: return "deflate stream longer than the data it should hold";
    default: return "deflate stream fails its Adler-32 check";
    }
}

/* ------------------------------------------------------------------------------------------ */
/* 3. deflate                                                                                 */
/* ------------------------------------------------------------------------------------------ */

/* Hash-chain LZ77: matches of 3..258 bytes within 32 KiB, the first EX_Z_CHAIN candidates of a
 * 3-byte hash examined (zlib's level-6 chain length is 128; 32 keeps the writer fast). */
#define EX_Z_CHAIN 32
#define EX_Z_HASH_BITS 15
#define EX_Z_WINDOW 32768

/* Upper bound of ex_deflate_zlib's output for n input bytes: the stored form (5 bytes per 65535)
 * plus the 2-byte header and 4-byte check; 0 when that overflows size_t. */
static inline size_t ex_deflate_bound(size_t n)
{
    size_t blocks = n / 65535u + 1u;
    if (n > SIZE_MAX - 6u - 5u * blocks || blocks > (SIZE_MAX - 6u) / 5u) return 0;
    return n + 5u * blocks + 6u;
}

typedef struct {
    unsigned char *out;
    size_t cap, pos;
    uint32_t bits;
    int nbits;
    int full; /* the output passed cap: the fixed-Huffman form is longer than the stored one */
} ex_z_writer;

static inline void ex_z_put(ex_z_writer *w, uint32_t v, int n)
{
    w->bits |= v << w->nbits;
    w->nbits += n;
    while (w->nbits >= 8) {
        if (w->pos < w->cap) w->out[w->pos++] = (unsigned char)w->bits;
        else w->full = 1;
        w->bits >>= 8;
        w->nbits -= 8;
    }
}

/* The fixed codes of RFC 1951 §3.2.6, made once per stream: each literal/length symbol's code
 * with its bits reversed (Huffman codes go most significant bit first, §3.1.1, and ex_z_put
 * fills from the least significant end) and its length; the 5-bit distance codes reversed; and
 * the symbol of every match length (3..258) and distance (1..32768: below 257 by the distance,
 * above by its bits past the seventh, as zlib's _dist_code). */
typedef struct {
    uint16_t lit_code[288];
    unsigned char lit_bits[288], len_sym[259], dist_rev[30], dist_sym[512];
} ex_z_fixed_codes;

static inline void ex_z_fixed_codes_init(ex_z_fixed_codes *t)
{
    int sym, i, d;
    for (sym = 0; sym < 288; sym++) {
        uint32_t code;
        int n;
        if (sym < 144) { code = 0x30u + (uint32_t)sym; n = 8; }
        else if (sym < 256) { code = 0x190u + (uint32_t)(sym - 144); n = 9; }
        else if (sym < 280) { code = (uint32_t)(sym - 256); n = 7; }
        else { code = 0xc0u + (uint32_t)(sym - 280); n = 8; }
        t->lit_code[sym] = (uint16_t)ex_z_reverse(code, n);
        t->lit_bits[sym] = (unsigned char)n;
    }
    for (i = 0; i < 29; i++) /* lengths: the last base at or below each length */
        for (d = ex_z_len_base[i]; d <= 258 && (i == 28 || d < ex_z_len_base[i + 1]); d++)
            t->len_sym[d] = (unsigned char)i;
    for (i = 0; i < 30; i++) {
        int lo = ex_z_dist_base[i], hi = i == 29 ? 32768 : ex_z_dist_base[i + 1] - 1;
        t->dist_rev[i] = (unsigned char)ex_z_reverse((uint32_t)i, 5);
        for (d = lo; d <= hi; d++) {
            if (d <= 256) t->dist_sym[d - 1] = (unsigned char)i;
            else t->dist_sym[256 + ((d - 1) >> 7)] = (unsigned char)i;
        }
    }
}

static inline void ex_z_put_lit(ex_z_writer *w, const ex_z_fixed_codes *t, int sym)
{
    ex_z_put(w, t->lit_code[sym], t->lit_bits[sym]);
}

static inline void ex_z_put_match(ex_z_writer *w, const ex_z_fixed_codes *t, int len, int dist)
{
    int i = t->len_sym[len], j = t->dist_sym[dist <= 256 ? dist - 1 : 256 + ((dist - 1) >> 7)];
    ex_z_put_lit(w, t, 257 + i);
    ex_z_put(w, (uint32_t)(len - ex_z_len_base[i]), ex_z_len_extra[i]);
    ex_z_put(w, t->dist_rev[j], 5);
    ex_z_put(w, (uint32_t)(dist - ex_z_dist_base[j]), ex_z_dist_extra[j]);
}

/* Compress in[0..n) as a zlib stream into out (capacity at least ex_deflate_bound(n)): one
 * fixed-Huffman block of greedy LZ77 matches, or stored blocks when those come out shorter.
 * *written = the stream length. Returns 0, or -1 (capacity short, or no memory for the hash
 * chains: 2^15 + 32768 ints). */
static inline int ex_deflate_zlib(const unsigned char *in, size_t n, unsigned char *out, size_t cap,
                                  size_t *written)
{
    size_t bound = ex_deflate_bound(n), i, stored;
    int32_t *head, *prev;
    ex_z_writer w;
    ex_z_fixed_codes codes;
    uint32_t adler = ex_adler32(1, in, n);
    if (bound == 0 || cap < bound) return -1;
    head = (int32_t *)malloc(sizeof(int32_t) << EX_Z_HASH_BITS);
    prev = (int32_t *)malloc(sizeof(int32_t) * EX_Z_WINDOW);
    if (!head || !prev) {
        free(head);
        free(prev);
        return -1;
    }
    for (i = 0; i < ((size_t)1 << EX_Z_HASH_BITS); i++) head[i] = -1;
    ex_z_fixed_codes_init(&codes);
    stored = bound - 6u; /* the stored form's length without header and check */
    memset(&w, 0, sizeof w);
    w.out = out + 2;
    w.cap = stored; /* the fixed form is used only when strictly shorter */
    ex_z_put(&w, 1u | (1u << 1), 3); /* BFINAL, BTYPE 01 */
    i = 0;
    /* Positions are kept relative to a base so the int32 chains work for any n: every 2^30
     * bytes the tables are cleared (a match never reaches across that seam). */
    while (i < n && !w.full) {
        size_t base = i - (i & (((size_t)1 << 30) - 1u)), best_len = 0, best_dist = 0;
        if (i + 2 < n) {
            uint32_t hsh = ((uint32_t)in[i] << 16 | (uint32_t)in[i + 1] << 8 | in[i + 2]) * 2654435761u
                           >> (32 - EX_Z_HASH_BITS);
            int32_t cand = head[hsh];
            int chain = EX_Z_CHAIN;
            size_t rel = i - base;
            if ((i & (((size_t)1 << 30) - 1u)) == 0 && i > 0) {
                size_t k;
                for (k = 0; k < ((size_t)1 << EX_Z_HASH_BITS); k++) head[k] = -1;
                cand = -1;
            }
            while (cand >= 0 && chain-- > 0 && rel - (size_t)cand <= EX_Z_WINDOW) {
                size_t c = base + (size_t)cand, len = 0, maxlen = n - i < 258 ? n - i : 258;
                /* a candidate beats the best only if it matches one byte further: test that
                 * byte first (zlib's trick; the same matches are chosen) */
                if (best_len > 0 && in[c + best_len] != in[i + best_len]) {
                    cand = prev[(size_t)cand & (EX_Z_WINDOW - 1)];
                    continue;
                }
                while (len < maxlen && in[c + len] == in[i + len]) len++;
                if (len > best_len) {
                    best_len = len;
                    best_dist = i - c;
                    if (len == maxlen) break;
                }
                cand = prev[(size_t)cand & (EX_Z_WINDOW - 1)];
            }
            prev[rel & (EX_Z_WINDOW - 1)] = head[hsh];
            head[hsh] = (int32_t)rel;
        }
        if (best_len >= 3) {
            size_t k;
            ex_z_put_match(&w, &codes, (int)best_len, (int)best_dist);
            /* insert the skipped positions into the chains */
            for (k = 1; k < best_len; k++) {
                size_t p = i + k, rel = p - base;
                uint32_t hsh;
                if (p + 2 >= n || (p & (((size_t)1 << 30) - 1u)) == 0) break;
                hsh = ((uint32_t)in[p] << 16 | (uint32_t)in[p + 1] << 8 | in[p + 2]) * 2654435761u
                      >> (32 - EX_Z_HASH_BITS);
                prev[rel & (EX_Z_WINDOW - 1)] = head[hsh];
                head[hsh] = (int32_t)rel;
            }
            i += best_len;
        } else {
            ex_z_put_lit(&w, &codes, in[i]);
            i++;
        }
    }
    ex_z_put_lit(&w, &codes, 256);
    ex_z_put(&w, 0, 7); /* flush the last byte */
    free(head);
    free(prev);
    out[0] = 0x78;
    out[1] = 0x01; /* CMF/FLG: deflate, 32 KiB window, 0x7801 % 31 == 0 */
    if (w.full || w.pos >= stored) {
        /* stored blocks of at most 65535 bytes (BFINAL on the last, LEN, NLEN) */
        size_t pos = 2, done = 0;
        do {
            size_t len = n - done < 65535u ? n - done : 65535u;
            out[pos] = (unsigned char)(done + len == n);
            out[pos + 1] = (unsigned char)(len & 0xffu);
            out[pos + 2] = (unsigned char)(len >> 8);
            out[pos + 3] = (unsigned char)(~len & 0xffu);
            out[pos + 4] = (unsigned char)((~len >> 8) & 0xffu);
            if (len) memcpy(out + pos + 5, in + done, len);
            pos += 5 + len;
            done += len;
        } while (done < n);
        w.pos = pos - 2;
    }
    out[2 + w.pos] = (unsigned char)(adler >> 24);
    out[3 + w.pos] = (unsigned char)(adler >> 16);
    out[4 + w.pos] = (unsigned char)(adler >> 8);
    out[5 + w.pos] = (unsigned char)adler;
    *written = w.pos + 6;
    return 0;
}

/* ------------------------------------------------------------------------------------------ */
/* 4. atomic files                                                                            */
/* ------------------------------------------------------------------------------------------ */

/* Told each temporary name once it exists and NULL before it is renamed or removed, so that a
 * program's signal handler can remove it on an interrupt (the hfvis CLI sets it, as it sets
 * hfvis_write_options.on_temp); NULL: nobody is told. */
static void (*ex_atomic_on_temp)(void *user, const char *tmp);

/* Told 1 before a step whose files an interrupt handler cannot know yet (a temporary file until
 * hfvis_write_begin has reported it; the renames of ex_publish_end, whose files it never knows)
 * and 0 after it: the hfvis CLI holds SIGINT, SIGTERM and SIGHUP meanwhile, so that an interrupt
 * finds every temporary file reported and a set of files whole, the old one or the new one.
 * NULL: nothing is held. */
static void (*ex_atomic_hold)(int hold);
static inline hfvis_status ex_atomic_begin(const char *path, const hfvis_write_options *wo, FILE **f,
                                           char **tmp)
{
    hfvis_status s;
    if (ex_atomic_hold) ex_atomic_hold(1);
    s = hfvis_write_begin(path, wo, f, tmp);
    if (ex_atomic_hold) ex_atomic_hold(0);
    return s;
}

/* The library's atomic write (hfvis_write_begin), reporting to ex_atomic_on_temp: the temporary
 * file beside path, open for writing, its name in *tmp_out for ex_atomic_close. NULL (and
 * *tmp_out NULL) on failure. */
static inline FILE *ex_atomic_open(const char *path, char **tmp_out)
{
    hfvis_write_options wo;
    FILE *f;
    wo.on_temp = ex_atomic_on_temp;
    wo.user = NULL;
    if (ex_atomic_begin(path, &wo, &f, tmp_out) != HFVIS_OK) return NULL;
    return f;
}

/* Finish a file from ex_atomic_open (hfvis_write_end): with ok, rename it onto path; otherwise
 * (or when flushing or closing fails) remove it, leaving path untouched. Frees tmp. Returns 1
 * when path now holds the new file. */
static inline int ex_atomic_close(FILE *f, char *tmp, const char *path, int ok)
{
    hfvis_write_options wo;
    wo.on_temp = ex_atomic_on_temp;
    wo.user = NULL;
    return hfvis_write_end(path, f, tmp, ok, &wo) == HFVIS_OK && ok;
}

/* A file and its sidecars (an ASCII grid and its .prj, a .bil and its .hdr and .prj) replaced
 * together, so that no failure leaves a new sidecar beside old data or the reverse: every new
 * file is written completely to its own temporary file first (ex_publish_open, then
 * ex_publish_close); ex_publish_end then moves each existing target aside, renames each new file
 * in (a target listed with ex_publish_absent, a stale sidecar the new output lacks, is only
 * moved aside) and, once all are in place, removes the old ones. When any write, close or
 * rename fails, the new files are removed and the old ones renamed back: every target is as it
 * was. An interrupt held by ex_atomic_hold during the renames finds the set whole (without the
 * hold it could leave the old files under their aside names "<target>.tmp<hex>"). */
#define EX_PUBLISH_MAX 4
typedef struct {
    int n, ok;
    const char *path[EX_PUBLISH_MAX]; /* the targets (the caller's strings) */
    char *tmp[EX_PUBLISH_MAX];        /* the closed temporary file of each, NULL: to be absent */
} ex_publish;

static inline void ex_publish_init(ex_publish *p)
{
    memset(p, 0, sizeof *p);
    p->ok = 1;
}

/* The temporary file of the next target, open for writing; NULL on failure (then the set fails). */
static inline FILE *ex_publish_open(ex_publish *p, const char *path)
{
    hfvis_write_options wo;
    FILE *f = NULL;
    char *tmp = NULL;
    if (!p->ok || p->n >= EX_PUBLISH_MAX) {
        p->ok = 0;
        return NULL;
    }
    wo.on_temp = ex_atomic_on_temp;
    wo.user = NULL;
    if (ex_atomic_begin(path, &wo, &f, &tmp) != HFVIS_OK) {
        p->ok = 0;
        return NULL;
    }
    p->path[p->n] = path;
    p->tmp[p->n++] = tmp;
    return f;
}

/* path is to be absent once the set is published (moved aside with the others, then removed). */
static inline void ex_publish_absent(ex_publish *p, const char *path)
{
    if (p->n >= EX_PUBLISH_MAX) {
        p->ok = 0;
        return;
    }
    p->path[p->n] = path;
    p->tmp[p->n++] = NULL;
}

/* Flush and close a file of ex_publish_open; ok 0 (a write of the caller failed), a write error
 * or a failed flush or close fails the set. */
static inline void ex_publish_close(ex_publish *p, FILE *f, int ok)
{
    if (!f) return;
    ok = HFVIS_FFLUSH(f) == 0 && !ferror(f) && ok;
    if (HFVIS_FCLOSE(f) != 0) ok = 0;
    if (!ok) p->ok = 0;
}

/* Publish the set (see above) and release it. Returns 1 when every target holds its new file
 * (or is absent as asked), 0 when every target is as it was. */
static inline int ex_publish_end(ex_publish *p)
{
    char *aside[EX_PUBLISH_MAX];
    int placed[EX_PUBLISH_MAX], i, ok = p->ok;
    for (i = 0; i < p->n; i++) {
        aside[i] = NULL;
        placed[i] = 0;
    }
    if (ex_atomic_hold) ex_atomic_hold(1); /* an interrupt waits for the whole set */
    for (i = 0; ok && i < p->n; i++) { /* the old files aside, under fresh temporary names */
        FILE *e = fopen(p->path[i], "rb"), *f = NULL;
        if (!e) continue; /* absent (an unreadable target fails at its rename below) */
        fclose(e);
        if (hfvis_write_begin(p->path[i], NULL, &f, &aside[i]) != HFVIS_OK) {
            ok = 0;
            break;
        }
        fclose(f);
        remove(aside[i]); /* the name is free again (Windows' rename does not replace) */
        if (HFVIS_RENAME(p->path[i], aside[i]) != 0) {
            hfvis_free(NULL, aside[i]);
            aside[i] = NULL;
            ok = 0;
        }
    }
    for (i = 0; ok && i < p->n; i++) /* the new files in */
        if (p->tmp[i]) ok = placed[i] = HFVIS_RENAME(p->tmp[i], p->path[i]) == 0;
    for (i = 0; i < p->n; i++) {
        if (!ok && placed[i]) remove(p->path[i]);
        if (aside[i]) {
            if (ok) remove(aside[i]);
            else HFVIS_RENAME(aside[i], p->path[i]); /* back (if this fails, the old file stays aside) */
            hfvis_free(NULL, aside[i]);
        }
        if (p->tmp[i]) {
            if (!placed[i]) remove(p->tmp[i]);
            hfvis_free(NULL, p->tmp[i]);
        }
    }
    if (ex_atomic_on_temp) ex_atomic_on_temp(NULL, NULL);
    if (ex_atomic_hold) ex_atomic_hold(0);
    p->n = 0;
    return ok;
}

#endif /* HFVIS_EXAMPLES_ZIO_H */
