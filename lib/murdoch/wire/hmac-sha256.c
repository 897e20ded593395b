/*  hmac-sha256.c -- HMAC-SHA256 (RFC 2104) for (murdoch wire hmac), by OpenSSL's
 *  libcrypto; hmac.stub binds it
 *
 *  Every frame of the remote layer is MAC'd once when sent and once when
 *  received.  Over Chibi's SHA-256 that cost 40 us a frame, nearly all of
 *  it Scheme building the byte strings HMAC hashes; here it is about a
 *  microsecond.  The hash and the constant-time comparison are
 *  libcrypto's (a well-kept library, not ours to get wrong); this file
 *  feeds it the pads and the parts of a frame, and builds Scheme strings
 *  of the result.
 *
 *  The HMAC (RFC 2104) is built here on libcrypto's SHA-256: the key's
 *  inner and outer pads are hashed once, and each MAC starts from a copy
 *  of those two states.  Chibi's threads are green threads on one OS
 *  thread, and a call into C is not interrupted by them, so one set of
 *  states serves every call; every frame of a process is under one key.
 *  OpenSSL 3's EVP_MAC, which this file used before, spent about 2,000
 *  instructions a MAC on its dispatch around the hash (docs/speed.md,
 *  "The receivers' share", sixth session).
 *
 *  The key and the parts come unchecked, and are looked at here: each may
 *  be of more than one type, which chibi-ffi's checks cannot say.
 */

#include <chibi/eval.h>
/* SHA256_Init and its kin are deprecated in OpenSSL 3 for EVP, whose
 * dispatch is what this file avoids; they remain in libcrypto. */
#define OPENSSL_SUPPRESS_DEPRECATED
#include <openssl/crypto.h>
#include <openssl/sha.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAC_SIZE 32                     /* SHA-256's digest */
#define BLOCK_SIZE 64                   /* and block */

/* The states after the inner and the outer pad of the key last given,
 * and the MAC being made. */
static SHA256_CTX inner_start, outer_start, mac_state;
/* A copy of the key the pads were made of, of keyed_length bytes; NULL
 * and -1 when there is none. */
static unsigned char *keyed;
static long keyed_length = -1;

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

/* Writes v's decimal digits at the end of buf, 24 bytes; answers where
 * they start: snprintf took 350 instructions a number, three a served
 * request (docs/speed.md). */
static char *decimal (char *buf, long v) {
  char *p = buf + 24;
  unsigned long u = v < 0 ? -(unsigned long)v : (unsigned long)v;
  do *--p = '0' + u % 10; while ((u /= 10) > 0);
  if (v < 0) *--p = '-';
  return p;
}

/* Hashes one part of a message: its bytes, or a fixnum's decimal digits,
 * which saves the caller number->string (a string port in Chibi, 25 us). */
static int hash_part (sexp part) {
  const unsigned char *p;
  size_t n;
  char digits[24], *d;
  if (sexp_fixnump(part)) {
    d = decimal(digits, (long)sexp_unbox_fixnum(part));
    return SHA256_Update(&mac_state, d, digits + 24 - d);
  }
  if (!bytes_of(part, &p, &n)) return 0;
  return SHA256_Update(&mac_state, p, n);
}

/* Forgets the key the pads were made of. */
static void forget_key (void) {
  if (keyed) {
    OPENSSL_cleanse(keyed, keyed_length);
    free(keyed);
  }
  keyed = NULL;
  keyed_length = -1;
}

/* The states after the pads of key, of kn bytes: RFC 2104's K0, the key
 * hashed when longer than a block, then zeros, xored with 0x36 and 0x5c. */
static int make_pads (const unsigned char *kp, size_t kn) {
  unsigned char block[BLOCK_SIZE];
  size_t i;
  int ok;
  memset(block, 0, sizeof block);
  if (kn > BLOCK_SIZE) SHA256(kp, kn, block);
  else memcpy(block, kp, kn);
  for (i = 0; i < BLOCK_SIZE; i++) block[i] ^= 0x36;
  ok = SHA256_Init(&inner_start) && SHA256_Update(&inner_start, block, BLOCK_SIZE);
  for (i = 0; i < BLOCK_SIZE; i++) block[i] ^= 0x36 ^ 0x5c;
  ok = ok && SHA256_Init(&outer_start) && SHA256_Update(&outer_start, block, BLOCK_SIZE);
  OPENSSL_cleanse(block, sizeof block);
  return ok;
}

/* Begins HMAC under key; 0 when the key is neither bytes nor text, or
 * libcrypto fails.  The key's bytes are compared, not the object, so a
 * bytevector changed in place is keyed afresh; by memcmp, as both are
 * this process's own key. */
static int hmac_begin (sexp key) {
  const unsigned char *kp;
  size_t kn;
  if (!bytes_of(key, &kp, &kn)) return 0;
  if (!(keyed && kn == (size_t)keyed_length && memcmp(kp, keyed, kn) == 0)) {
    forget_key();
    if (!make_pads(kp, kn)) return 0;
    if ((keyed = malloc(kn ? kn : 1))) { /* else keyed afresh next time */
      memcpy(keyed, kp, kn);
      keyed_length = kn;
    }
  }
  mac_state = inner_start;
  return 1;
}

/* Hashes the parts of a Scheme list: the empty list when all are bytes,
 * text or fixnums; else the pair of the first that is not, or the list's
 * end that is not the empty list.  A frame's (NONCE . COUNT), COUNT a
 * fixnum, stands for the parts NONCE ":" COUNT ":" (wire/frame.scm): a
 * pair a frame, where the list took four. */
static sexp hash_parts (sexp ls) {
  if (sexp_pairp(ls) && sexp_fixnump(sexp_cdr(ls)))
    return hash_part(sexp_car(ls)) && SHA256_Update(&mac_state, ":", 1)
      && hash_part(sexp_cdr(ls)) && SHA256_Update(&mac_state, ":", 1)
      ? SEXP_NULL : ls;
  for ( ; sexp_pairp(ls); ls = sexp_cdr(ls))
    if (!hash_part(sexp_car(ls)))
      return ls;
  return ls;
}

/* Begins HMAC under key and hashes the parts: SEXP_VOID, or the type
 * exception that names the key or the first part that is neither bytes,
 * text nor a fixnum.  Every primitive below starts so. */
static sexp hmac_begin_parts (sexp ctx, sexp self, sexp key, sexp parts) {
  const unsigned char *p;
  size_t n;
  sexp bad;
  if (!hmac_begin(key))
    return bytes_of(key, &p, &n)
      ? sexp_user_exception(ctx, self, "libcrypto: HMAC failed", key)
      : sexp_type_exception(ctx, self, SEXP_BYTES, key);
  if ((bad = hash_parts(parts)) != SEXP_NULL)
    return sexp_pairp(bad)
      ? sexp_type_exception(ctx, self, SEXP_BYTES, sexp_car(bad))
      : sexp_type_exception(ctx, self, SEXP_PAIR, parts);
  return SEXP_VOID;
}

/* The MAC of what was hashed since hmac_begin, as 64 lowercase hex digits
 * in text; 0 when libcrypto fails. */
static int hmac_end (char text[2 * MAC_SIZE]) {
  static const char hex[] = "0123456789abcdef";
  unsigned char digest[MAC_SIZE];
  SHA256_CTX outer = outer_start;
  size_t i;
  if (!SHA256_Final(digest, &mac_state)
      || !SHA256_Update(&outer, digest, MAC_SIZE) || !SHA256_Final(digest, &outer))
    return 0;
  for (i = 0; i < MAC_SIZE; i++) {
    text[2*i] = hex[digest[i] >> 4];
    text[2*i+1] = hex[digest[i] & 15];
  }
  return 1;
}

static sexp libcrypto_failed (sexp ctx, sexp self) {
  return sexp_user_exception(ctx, self, "libcrypto: HMAC failed", SEXP_NULL);
}

/* (%hmac-sha256 key parts): the MAC under key (a bytevector or string)
 * of the parts one after the other (bytevectors, strings as UTF-8, and
 * fixnums in decimal), as a lowercase hex string. */
static sexp hmac_sha256 (sexp ctx, sexp self, sexp key, sexp parts) {
  char text[64];
  sexp res;
  res = hmac_begin_parts(ctx, self, key, parts);
  if (res != SEXP_VOID) return res;
  if (!hmac_end(text)) return libcrypto_failed(ctx, self);
  return sexp_c_string(ctx, text, 64);
}

/* The MAC, as hex digits in mac, under key of the parts followed by the
 * tn bytes at tp: SEXP_VOID, or the exception. */
static sexp mac_of_text (sexp ctx, sexp self, sexp key, sexp parts,
                         const char *tp, long tn, char mac[64]) {
  sexp res = hmac_begin_parts(ctx, self, key, parts);
  if (res != SEXP_VOID) return res;
  if (!SHA256_Update(&mac_state, tp, tn)
      || !hmac_end(mac))
    return libcrypto_failed(ctx, self);
  return SEXP_VOID;
}

/* (hmac-sha256-sign key text parts): text, of tn bytes at tp, signed: a
 * string of the MAC under key of the parts followed by text, then text
 * itself.  One call where a frame took a MAC and a string-append. */
static sexp hmac_sha256_sign (sexp ctx, sexp self, sexp key,
                              const char *tp, long tn, sexp parts) {
  char mac[64];
  sexp res = mac_of_text(ctx, self, key, parts, tp, tn, mac);
  if (res != SEXP_VOID) return res;
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

/* (hmac-sha256-write! key text parts port): writes to port the netstring
 * whose payload is text signed as hmac-sha256-sign signs it, "LENGTH:"
 * MAC text ",", and makes nothing: the signed string and the netstring's
 * writes in Scheme made 1.9 KB of garbage a frame. */
static sexp hmac_sha256_write (sexp ctx, sexp self, sexp key, const char *tp,
                               long tn, sexp parts, sexp port) {
  char mac[64], length[25], *d;
  sexp res;
  if (!sexp_oportp(port) || !sexp_port_openp(port))
    return sexp_xtype_exception(ctx, self, "not an open output port", port);
  res = mac_of_text(ctx, self, key, parts, tp, tn, mac);
  if (res != SEXP_VOID) return res;
  length[24] = ':';
  d = decimal(length, 64 + tn);
  if (sexp_write_string_n(ctx, d, length + 25 - d, port) < 0
      || sexp_write_string_n(ctx, mac, 64, port) < 0
      || sexp_write_string_n(ctx, tp, tn, port) < 0
      || sexp_write_char(ctx, ',', port) < 0)
    return sexp_user_exception(ctx, self, "cannot write the frame", port);
  return SEXP_VOID;
}

/* (hmac-sha256-write-text! key text-port parts port max): as
 * hmac-sha256-write! of the text written to text-port, a string output
 * port emptied by reset-output-string! (netstring-scan.c) before it,
 * taken from the port's buffer: get-output-string made four objects a
 * frame (docs/speed.md, "The receivers' share", sixth session).  #t once
 * written; the symbol too-large, writing nothing, when the frame would
 * be over max bytes; #f, writing nothing, when the text outgrew the
 * port's buffer, for the caller to take by get-output-string. */
static sexp hmac_sha256_write_text (sexp ctx, sexp self, sexp key, sexp text_port,
                                    sexp parts, sexp port, long max) {
  sexp res;
  if (!sexp_oportp(text_port) || !sexp_pairp(sexp_port_cookie(text_port))
      || sexp_filenop(sexp_port_fd(text_port)))
    return sexp_xtype_exception(ctx, self, "not a string output port", text_port);
  if (sexp_cdr(sexp_port_cookie(text_port)) != SEXP_NULL) return SEXP_FALSE;
  if (64 + (long)sexp_port_offset(text_port) > max)
    return sexp_intern(ctx, "too-large", -1);
  res = hmac_sha256_write(ctx, self, key, sexp_port_buf(text_port),
                          sexp_port_offset(text_port), parts, port);
  return res == SEXP_VOID ? SEXP_TRUE : res;
}

/* (hmac-sha256-open key bytes end parts): the text that follows the 64
 * hex digits of a MAC in the first end bytes of bytes (of size bytes at
 * data), as a string, when the MAC is that under key of the parts
 * followed by the text; #f when it is not, or there are fewer than 64
 * bytes.  The text's bytes are taken as they are: bytes that are not
 * UTF-8 fail the MAC or the reader. */
static sexp hmac_sha256_open (sexp ctx, sexp self, sexp key, const char *data,
                              long size, long end, sexp parts) {
  char mac[64];
  sexp res;
  if (end < 0 || end > size)
    return sexp_user_exception(ctx, self, "end out of range",
                               sexp_make_integer(ctx, end));
  if (end < 64) return SEXP_FALSE;
  res = hmac_begin_parts(ctx, self, key, parts);
  if (res != SEXP_VOID) return res;
  if (!SHA256_Update(&mac_state, data + 64, end - 64)
      || !hmac_end(mac))
    return libcrypto_failed(ctx, self);
  if (CRYPTO_memcmp(mac, data, 64) != 0) return SEXP_FALSE;
  return sexp_c_string(ctx, data + 64, end - 64);
}
