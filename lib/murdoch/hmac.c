/*  hmac.c -- HMAC-SHA256 (RFC 2104, FIPS 180-4) for (murdoch hmac)
 *
 *  Every frame of the remote layer is MAC'd once when sent and once when
 *  received.  Over Chibi's SHA-256 that cost 40 us a frame, nearly all of
 *  it Scheme building the byte strings HMAC hashes; here it is about a
 *  microsecond.
 */

#include <chibi/eval.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* The first 32 bits of the fractional parts of the cube roots of the
 * first 64 primes, and of the square roots of the first 8. */
static const uint32_t k[64] = {
  0x428a2f98u, 0x71374491u, 0xb5c0fbcfu, 0xe9b5dba5u,
  0x3956c25bu, 0x59f111f1u, 0x923f82a4u, 0xab1c5ed5u,
  0xd807aa98u, 0x12835b01u, 0x243185beu, 0x550c7dc3u,
  0x72be5d74u, 0x80deb1feu, 0x9bdc06a7u, 0xc19bf174u,
  0xe49b69c1u, 0xefbe4786u, 0x0fc19dc6u, 0x240ca1ccu,
  0x2de92c6fu, 0x4a7484aau, 0x5cb0a9dcu, 0x76f988dau,
  0x983e5152u, 0xa831c66du, 0xb00327c8u, 0xbf597fc7u,
  0xc6e00bf3u, 0xd5a79147u, 0x06ca6351u, 0x14292967u,
  0x27b70a85u, 0x2e1b2138u, 0x4d2c6dfcu, 0x53380d13u,
  0x650a7354u, 0x766a0abbu, 0x81c2c92eu, 0x92722c85u,
  0xa2bfe8a1u, 0xa81a664bu, 0xc24b8b70u, 0xc76c51a3u,
  0xd192e819u, 0xd6990624u, 0xf40e3585u, 0x106aa070u,
  0x19a4c116u, 0x1e376c08u, 0x2748774cu, 0x34b0bcb5u,
  0x391c0cb3u, 0x4ed8aa4au, 0x5b9cca4fu, 0x682e6ff3u,
  0x748f82eeu, 0x78a5636fu, 0x84c87814u, 0x8cc70208u,
  0x90befffau, 0xa4506cebu, 0xbef9a3f7u, 0xc67178f2u
};

static const uint32_t h0[8] = {
  0x6a09e667u, 0xbb67ae85u, 0x3c6ef372u, 0xa54ff53au,
  0x510e527fu, 0x9b05688cu, 0x1f83d9abu, 0x5be0cd19u
};

struct sha256 {
  uint32_t h[8];
  unsigned char block[64];
  size_t used;          /* bytes in block */
  uint64_t length;      /* bytes hashed so far */
};

#define ROTR(x, n) (((x) >> (n)) | ((x) << (32 - (n))))

static void compress (uint32_t h[8], const unsigned char *p) {
  uint32_t w[64], a, b, c, d, e, f, g, hh, t1, t2;
  int i;
  for (i = 0; i < 16; i++)
    w[i] = (uint32_t)p[4*i] << 24 | (uint32_t)p[4*i+1] << 16
      | (uint32_t)p[4*i+2] << 8 | p[4*i+3];
  for (i = 16; i < 64; i++)
    w[i] = (ROTR(w[i-2], 17) ^ ROTR(w[i-2], 19) ^ (w[i-2] >> 10)) + w[i-7]
      + (ROTR(w[i-15], 7) ^ ROTR(w[i-15], 18) ^ (w[i-15] >> 3)) + w[i-16];
  a = h[0]; b = h[1]; c = h[2]; d = h[3];
  e = h[4]; f = h[5]; g = h[6]; hh = h[7];
  for (i = 0; i < 64; i++) {
    t1 = hh + (ROTR(e, 6) ^ ROTR(e, 11) ^ ROTR(e, 25)) + ((e & f) ^ (~e & g))
      + k[i] + w[i];
    t2 = (ROTR(a, 2) ^ ROTR(a, 13) ^ ROTR(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
    hh = g; g = f; f = e; e = d + t1;
    d = c; c = b; b = a; a = t1 + t2;
  }
  h[0] += a; h[1] += b; h[2] += c; h[3] += d;
  h[4] += e; h[5] += f; h[6] += g; h[7] += hh;
}

static void sha256_init (struct sha256 *s) {
  memcpy(s->h, h0, sizeof h0);
  s->used = 0;
  s->length = 0;
}

static void sha256_update (struct sha256 *s, const unsigned char *p, size_t n) {
  s->length += n;
  while (n > 0) {
    size_t take = 64 - s->used < n ? 64 - s->used : n;
    memcpy(s->block + s->used, p, take);
    s->used += take; p += take; n -= take;
    if (s->used == 64) {
      compress(s->h, s->block);
      s->used = 0;
    }
  }
}

static void sha256_final (struct sha256 *s, unsigned char out[32]) {
  uint64_t bits = s->length * 8;
  unsigned char pad[72] = {0x80};
  size_t padding = (s->used < 56 ? 56 : 120) - s->used;
  int i;
  for (i = 0; i < 8; i++)
    pad[padding + i] = (unsigned char)(bits >> (56 - 8*i));
  sha256_update(s, pad, padding + 8);
  for (i = 0; i < 8; i++) {
    out[4*i] = s->h[i] >> 24; out[4*i+1] = s->h[i] >> 16;
    out[4*i+2] = s->h[i] >> 8; out[4*i+3] = s->h[i];
  }
}

/* The bytes of a bytevector, or of a string's UTF-8. */
static int bytes_of (sexp x, const unsigned char **p, size_t *n) {
  if (sexp_bytesp(x)) {
    *p = (const unsigned char *)sexp_bytes_data(x);
    *n = sexp_bytes_length(x);
  } else if (sexp_stringp(x)) {
    *p = (const unsigned char *)sexp_string_data(x);
    *n = sexp_string_size(x);
  } else {
    return 0;
  }
  return 1;
}

/* Hashes one part of a message: its bytes, or a fixnum's decimal digits,
 * which saves the caller number->string (a string port in Chibi, 25 us). */
static int hash_part (struct sha256 *s, sexp part) {
  const unsigned char *p;
  size_t n;
  char digits[32];
  if (sexp_fixnump(part)) {
    n = snprintf(digits, sizeof digits, "%ld", (long)sexp_unbox_fixnum(part));
    sha256_update(s, (const unsigned char *)digits, n);
    return 1;
  }
  if (!bytes_of(part, &p, &n)) return 0;
  sha256_update(s, p, n);
  return 1;
}

/* The inner hash of HMAC under key, begun: the caller adds the message
 * and passes the state to hmac_end.  0 when the key is neither bytes nor
 * text. */
static int hmac_begin (struct sha256 *s, unsigned char block[64], sexp key) {
  const unsigned char *kp;
  size_t kn, i;
  if (!bytes_of(key, &kp, &kn)) return 0;
  memset(block, 0, 64);
  if (kn > 64) {                 /* a long key is hashed first */
    sha256_init(s); sha256_update(s, kp, kn); sha256_final(s, block);
  } else {
    memcpy(block, kp, kn);
  }
  for (i = 0; i < 64; i++) block[i] ^= 0x36;
  sha256_init(s); sha256_update(s, block, 64);
  return 1;
}

/* Hashes the parts of a Scheme list; the first that is not bytes, text or
 * a fixnum, or SEXP_NULL when all are. */
static sexp hash_parts (struct sha256 *s, sexp ls) {
  for ( ; sexp_pairp(ls); ls = sexp_cdr(ls))
    if (!hash_part(s, sexp_car(ls)))
      return sexp_car(ls);
  return SEXP_NULL;
}

/* Begins HMAC under key and hashes the parts: SEXP_VOID, or the type
 * exception that names the key or the first part that is neither bytes,
 * text nor a fixnum.  Every primitive below starts so. */
static sexp hmac_begin_parts (sexp ctx, sexp self, struct sha256 *s,
                              unsigned char block[64], sexp key, sexp parts) {
  sexp bad;
  if (!hmac_begin(s, block, key))
    return sexp_type_exception(ctx, self, SEXP_BYTES, key);
  if ((bad = hash_parts(s, parts)) != SEXP_NULL)
    return sexp_type_exception(ctx, self, SEXP_BYTES, bad);
  return SEXP_VOID;
}

/* The MAC, as 64 lowercase hex digits, from the state hmac_begin began. */
static void hmac_end (struct sha256 *s, unsigned char block[64], char text[64]) {
  static const char hex[] = "0123456789abcdef";
  unsigned char digest[32];
  size_t i;
  sha256_final(s, digest);
  for (i = 0; i < 64; i++) block[i] ^= 0x36 ^ 0x5c;
  sha256_init(s); sha256_update(s, block, 64); sha256_update(s, digest, 32);
  sha256_final(s, digest);
  for (i = 0; i < 32; i++) {
    text[2*i] = hex[digest[i] >> 4];
    text[2*i+1] = hex[digest[i] & 15];
  }
}

/* (hmac-sha256 key part ...): the MAC under key (a bytevector or string)
 * of the parts one after the other (bytevectors, strings as UTF-8, and
 * fixnums in decimal), as a lowercase hex string. */
static sexp hmac_sha256 (sexp ctx, sexp self, sexp_sint_t n, sexp args) {
  unsigned char block[64];
  char text[64];
  struct sha256 s;
  sexp res;
  if (!sexp_pairp(args))
    return sexp_user_exception(ctx, self, "no key", args);
  res = hmac_begin_parts(ctx, self, &s, block, sexp_car(args), sexp_cdr(args));
  if (res != SEXP_VOID) return res;
  hmac_end(&s, block, text);
  return sexp_c_string(ctx, text, 64);
}

/* (hmac-sha256-sign key text part ...): text signed, a string of the MAC
 * under key of the parts followed by text, then text itself.  One call
 * where a frame took a MAC and a string-append. */
static sexp hmac_sha256_sign (sexp ctx, sexp self, sexp_sint_t n, sexp args) {
  unsigned char block[64];
  char mac[64];
  struct sha256 s;
  const unsigned char *tp;
  size_t tn;
  sexp res;
  if (!sexp_pairp(args) || !sexp_pairp(sexp_cdr(args)))
    return sexp_user_exception(ctx, self, "expected a key and a text", args);
  if (!sexp_stringp(sexp_cadr(args)))
    return sexp_type_exception(ctx, self, SEXP_STRING, sexp_cadr(args));
  res = hmac_begin_parts(ctx, self, &s, block, sexp_car(args), sexp_cddr(args));
  if (res != SEXP_VOID) return res;
  tp = (const unsigned char *)sexp_string_data(sexp_cadr(args));
  tn = sexp_string_size(sexp_cadr(args));
  sha256_update(&s, tp, tn);
  hmac_end(&s, block, mac);
  /* Built in place, as sexp_c_string builds a string: the collector does
   * not move the text, so tp stays good. */
  res = sexp_make_string(ctx, sexp_make_fixnum(64 + tn), SEXP_VOID);
  if (sexp_exceptionp(res)) return res;
  memcpy(sexp_string_data(res), mac, 64);
  memcpy(sexp_string_data(res) + 64, tp, tn);
  sexp_string_data(res)[64 + tn] = '\0';
  sexp_update_string_index_lookup(ctx, res);
  return res;
}

/* (hmac-sha256-open key bytes end part ...): the text that follows the 64
 * hex digits of a MAC in the first end bytes of bytes, as a string, when
 * the MAC is that under key of the parts followed by the text; #f when it
 * is not, or there are fewer than 64 bytes.  The text's bytes are taken as
 * they are: bytes that are not UTF-8 fail the MAC or the reader. */
static sexp hmac_sha256_open (sexp ctx, sexp self, sexp_sint_t n, sexp args) {
  unsigned char block[64], diff = 0;
  char mac[64];
  struct sha256 s;
  sexp bytes, end, res;
  sexp_sint_t e, i;
  if (!sexp_pairp(args) || !sexp_pairp(sexp_cdr(args))
      || !sexp_pairp(sexp_cddr(args)))
    return sexp_user_exception(ctx, self, "expected a key, bytes and an end", args);
  bytes = sexp_cadr(args);
  end = sexp_car(sexp_cddr(args));
  if (!sexp_bytesp(bytes))
    return sexp_type_exception(ctx, self, SEXP_BYTES, bytes);
  if (!sexp_fixnump(end))
    return sexp_type_exception(ctx, self, SEXP_FIXNUM, end);
  e = sexp_unbox_fixnum(end);
  if (e < 0 || (sexp_uint_t)e > sexp_bytes_length(bytes))
    return sexp_user_exception(ctx, self, "end out of range", end);
  if (e < 64) return SEXP_FALSE;
  res = hmac_begin_parts(ctx, self, &s, block, sexp_car(args),
                         sexp_cdr(sexp_cddr(args)));
  if (res != SEXP_VOID) return res;
  sha256_update(&s, (const unsigned char *)sexp_bytes_data(bytes) + 64, e - 64);
  hmac_end(&s, block, mac);
  for (i = 0; i < 64; i++)
    diff |= mac[i] ^ sexp_bytes_data(bytes)[i];
  if (diff) return SEXP_FALSE;
  return sexp_c_string(ctx, sexp_bytes_data(bytes) + 64, e - 64);
}

sexp sexp_init_library (sexp ctx, sexp self, sexp_sint_t n, sexp env,
                        const char *version, const sexp_abi_identifier_t abi) {
  if (!(sexp_version_compatible(ctx, version, sexp_version)
        && sexp_abi_compatible(ctx, abi, SEXP_ABI_IDENTIFIER)))
    return SEXP_ABI_ERROR;
  sexp_define_foreign_proc_rest(ctx, env, "hmac-sha256", 0, hmac_sha256);
  sexp_define_foreign_proc_rest(ctx, env, "hmac-sha256-sign", 0, hmac_sha256_sign);
  sexp_define_foreign_proc_rest(ctx, env, "hmac-sha256-open", 0, hmac_sha256_open);
  return SEXP_VOID;
}
