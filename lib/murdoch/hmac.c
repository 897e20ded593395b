/*  hmac.c -- HMAC-SHA256 (RFC 2104) for (murdoch hmac), by OpenSSL's libcrypto
 *
 *  Every frame of the remote layer is MAC'd once when sent and once when
 *  received.  Over Chibi's SHA-256 that cost 40 us a frame, nearly all of
 *  it Scheme building the byte strings HMAC hashes; here it is about a
 *  microsecond.  The hash, the HMAC and the constant-time comparison are
 *  libcrypto's (a well-kept library, not ours to get wrong); this file only
 *  feeds it the parts of a frame and builds Scheme strings of the result.
 *
 *  One HMAC context serves every call: Chibi's threads are green threads
 *  on one OS thread, and a call into C is not interrupted by them.
 */

#define OPENSSL_API_COMPAT 0x10100000L  /* HMAC_CTX: one call a step */
#include <chibi/eval.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <stdio.h>
#include <string.h>

static HMAC_CTX *hmac_context;

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
static int hash_part (sexp part) {
  const unsigned char *p;
  size_t n;
  char digits[32];
  if (sexp_fixnump(part)) {
    n = snprintf(digits, sizeof digits, "%ld", (long)sexp_unbox_fixnum(part));
    return HMAC_Update(hmac_context, (const unsigned char *)digits, n);
  }
  if (!bytes_of(part, &p, &n)) return 0;
  return HMAC_Update(hmac_context, p, n);
}

/* Begins HMAC under key; 0 when the key is neither bytes nor text, or
 * libcrypto fails. */
static int hmac_begin (sexp key) {
  const unsigned char *kp;
  size_t kn;
  if (!bytes_of(key, &kp, &kn)) return 0;
  return HMAC_Init_ex(hmac_context, kp, kn, EVP_sha256(), NULL);
}

/* Hashes the parts of a Scheme list; the first that is not bytes, text or
 * a fixnum, or SEXP_NULL when all are. */
static sexp hash_parts (sexp ls) {
  for ( ; sexp_pairp(ls); ls = sexp_cdr(ls))
    if (!hash_part(sexp_car(ls)))
      return sexp_car(ls);
  return SEXP_NULL;
}

/* Begins HMAC under key and hashes the parts: SEXP_VOID, or the type
 * exception that names the key or the first part that is neither bytes,
 * text nor a fixnum.  Every primitive below starts so. */
static sexp hmac_begin_parts (sexp ctx, sexp self, sexp key, sexp parts) {
  sexp bad;
  if (!hmac_begin(key))
    return sexp_type_exception(ctx, self, SEXP_BYTES, key);
  if ((bad = hash_parts(parts)) != SEXP_NULL)
    return sexp_type_exception(ctx, self, SEXP_BYTES, bad);
  return SEXP_VOID;
}

/* The MAC of what was hashed since hmac_begin, as 64 lowercase hex digits. */
static void hmac_end (char text[64]) {
  static const char hex[] = "0123456789abcdef";
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int n = 0, i;
  HMAC_Final(hmac_context, digest, &n);
  for (i = 0; i < 32; i++) {
    text[2*i] = hex[digest[i] >> 4];
    text[2*i+1] = hex[digest[i] & 15];
  }
}

/* (hmac-sha256 key part ...): the MAC under key (a bytevector or string)
 * of the parts one after the other (bytevectors, strings as UTF-8, and
 * fixnums in decimal), as a lowercase hex string. */
static sexp hmac_sha256 (sexp ctx, sexp self, sexp_sint_t n, sexp args) {
  char text[64];
  sexp res;
  if (!sexp_pairp(args))
    return sexp_user_exception(ctx, self, "no key", args);
  res = hmac_begin_parts(ctx, self, sexp_car(args), sexp_cdr(args));
  if (res != SEXP_VOID) return res;
  hmac_end(text);
  return sexp_c_string(ctx, text, 64);
}

/* (hmac-sha256-sign key text part ...): text signed, a string of the MAC
 * under key of the parts followed by text, then text itself.  One call
 * where a frame took a MAC and a string-append. */
static sexp hmac_sha256_sign (sexp ctx, sexp self, sexp_sint_t n, sexp args) {
  char mac[64];
  const unsigned char *tp;
  size_t tn;
  sexp res;
  if (!sexp_pairp(args) || !sexp_pairp(sexp_cdr(args)))
    return sexp_user_exception(ctx, self, "expected a key and a text", args);
  if (!sexp_stringp(sexp_cadr(args)))
    return sexp_type_exception(ctx, self, SEXP_STRING, sexp_cadr(args));
  res = hmac_begin_parts(ctx, self, sexp_car(args), sexp_cddr(args));
  if (res != SEXP_VOID) return res;
  tp = (const unsigned char *)sexp_string_data(sexp_cadr(args));
  tn = sexp_string_size(sexp_cadr(args));
  HMAC_Update(hmac_context, tp, tn);
  hmac_end(mac);
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
  char mac[64];
  sexp bytes, end, res;
  sexp_sint_t e;
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
  res = hmac_begin_parts(ctx, self, sexp_car(args), sexp_cdr(sexp_cddr(args)));
  if (res != SEXP_VOID) return res;
  HMAC_Update(hmac_context, (const unsigned char *)sexp_bytes_data(bytes) + 64,
              e - 64);
  hmac_end(mac);
  if (CRYPTO_memcmp(mac, sexp_bytes_data(bytes), 64) != 0) return SEXP_FALSE;
  return sexp_c_string(ctx, sexp_bytes_data(bytes) + 64, e - 64);
}

sexp sexp_init_library (sexp ctx, sexp self, sexp_sint_t n, sexp env,
                        const char *version, const sexp_abi_identifier_t abi) {
  if (!(sexp_version_compatible(ctx, version, sexp_version)
        && sexp_abi_compatible(ctx, abi, SEXP_ABI_IDENTIFIER)))
    return SEXP_ABI_ERROR;
  if (!hmac_context && !(hmac_context = HMAC_CTX_new()))
    return sexp_user_exception(ctx, self, "libcrypto: no HMAC context", SEXP_NULL);
  sexp_define_foreign_proc_rest(ctx, env, "hmac-sha256", 0, hmac_sha256);
  sexp_define_foreign_proc_rest(ctx, env, "hmac-sha256-sign", 0, hmac_sha256_sign);
  sexp_define_foreign_proc_rest(ctx, env, "hmac-sha256-open", 0, hmac_sha256_open);
  return SEXP_VOID;
}
