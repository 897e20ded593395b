/*  netstring-scan.c -- the C of (murdoch wire netstring), which netstring.stub binds
 *
 *  Chibi's read-bytevector! is a Scheme loop of read-u8, about a third of
 *  a microsecond a byte: 50 us for a small frame, more than the rest of a
 *  remote-apply's reading.  The bytes are already in the port's buffer in
 *  C; this copies them out at once.  It never reads the descriptor itself:
 *  when the buffer is empty the Scheme side calls read-u8, which refills
 *  it and, on a socket with nothing to read, blocks only its own green
 *  thread, as every Chibi port read does.
 *
 *  The ports come unchecked and are looked at here: chibi-ffi's port
 *  types are for ports on a C stream (FILE *), which a socket's are not.
 */

#include <chibi/eval.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define assert_input_port(port)                                 \
  if (!sexp_iportp(port))                                       \
    return sexp_type_exception(ctx, self, SEXP_IPORT, port)

/* How many bytes the input port's buffer holds, read from the descriptor
 * but not yet from the port. */
static sexp_sint_t buffered (sexp port) {
  if (!sexp_port_buf(port) || sexp_port_offset(port) >= sexp_port_size(port))
    return 0;
  return sexp_port_size(port) - sexp_port_offset(port);
}

/* (read-buffered-bytes! port bytevector start end): copies what the
 * port's buffer holds, up to end - start bytes, into bytevector from
 * start; answers how many (0 when the buffer is empty or the port has
 * none). */
static sexp read_buffered_bytes (sexp ctx, sexp self, sexp port, char *bytes,
                                 long size, long from, long to) {
  sexp_sint_t have;
  assert_input_port(port);
  if (from < 0 || to < from || to > size)
    return sexp_user_exception(ctx, self, "bad range",
                               sexp_list2(ctx, sexp_make_integer(ctx, from),
                                          sexp_make_integer(ctx, to)));
  have = buffered(port);
  if (have == 0) return SEXP_ZERO;
  if (have > to - from) have = to - from;
  memcpy(bytes + from,
         sexp_port_buf(port) + sexp_port_offset(port), have);
  sexp_port_offset(port) += have;
  return sexp_make_fixnum(have);
}

/* (take-buffered-netstring port max): the payload, as a bytevector, of a
 * netstring that the port's buffer holds whole, taken from the buffer; #f,
 * taking nothing, when the buffer holds less than that or anything that
 * read-netstring would refuse.  read-netstring then reads byte by byte,
 * which waits for the rest and says what is wrong.  A frame usually
 * arrives whole, and this saves reading its length a byte at a time in
 * Scheme. */
static sexp take_buffered_netstring (sexp ctx, sexp self, sexp port,
                                     long most) {
  const unsigned char *start, *p, *end;
  sexp_sint_t len = 0;
  sexp payload;
  assert_input_port(port);
  if (buffered(port) == 0) return SEXP_FALSE;
  p = start = (const unsigned char *)sexp_port_buf(port) + sexp_port_offset(port);
  end = (const unsigned char *)sexp_port_buf(port) + sexp_port_size(port);
  if (*p == '0' && p + 1 < end && p[1] != ':') return SEXP_FALSE;
  for ( ; p < end && *p >= '0' && *p <= '9'; p++) {
    if (len > most / 10) return SEXP_FALSE;   /* before it can overflow */
    len = len * 10 + (*p - '0');
    if (len > most) return SEXP_FALSE;
  }
  if (p == end || *p != ':' || p == start
      || end - (p + 1) < len + 1 || p[1 + len] != ',')
    return SEXP_FALSE;
  payload = sexp_make_bytes(ctx, sexp_make_fixnum(len), SEXP_ZERO);
  if (sexp_exceptionp(payload)) return payload;
  memcpy(sexp_bytes_data(payload), p + 1, len);
  sexp_port_offset(port) = (char *)(p + 2 + len) - sexp_port_buf(port);
  return payload;
}

/* (buffered-byte-count port): what the buffer holds (see buffered).  Lets
 * a reader see that more frames have arrived without waiting for them. */
static sexp buffered_byte_count (sexp ctx, sexp self, sexp port) {
  assert_input_port(port);
  return sexp_make_fixnum(buffered(port));
}

/* (reset-output-string! port): empties a string output port, keeping its
 * buffer, so that one port can build frame after frame.  A new string
 * port costs a 4 KB buffer from Chibi's heap, and allocating that much
 * at a time, a frame at a time, was a good part of a message's cost. */
static sexp reset_output_string (sexp ctx, sexp self, sexp port) {
  if (!sexp_oportp(port) || !sexp_pairp(sexp_port_cookie(port))
      || sexp_filenop(sexp_port_fd(port)))
    return sexp_xtype_exception(ctx, self, "not a string output port", port);
  sexp_port_offset(port) = 0;
  sexp_cdr(sexp_port_cookie(port)) = SEXP_NULL;
  return SEXP_VOID;
}

/* (fixnum->decimal n): n in decimal.  Chibi's number->string writes to
 * a string port, which costs 25 us; a frame's length needs it each time. */
static sexp fixnum_to_decimal (sexp ctx, long x) {
  char digits[32];
  return sexp_c_string(ctx, digits, snprintf(digits, sizeof digits, "%ld", x));
}

/* Nesting.  Chibi's reader, in C, recurses for each level of nesting of
 * what it reads, without bound, and reads datum labels, which make
 * circular data.  A message is input from the network, so before it is
 * read its text is scanned here: how deep it nests, counting each list or
 * vector and each quote prefix (which the reader also reads by
 * recursion), and whether it holds a label (#N= or #N#), which our writer
 * never writes.  Strings, |symbols|, characters and comments are stepped
 * over as the reader steps over them.
 *
 * A quote prefix nests the datum after it, however far that datum then
 * nests inside: so a level opened after quotes costs one more for each,
 * and gives it all back when it closes; quotes before an atom give theirs
 * back with the atom.  Levels with quotes are few and remembered in
 * `costly', allocated only if one comes. */
struct nesting {
  long depth, limit, quotes, levels;  /* levels: open lists and vectors */
  long *costly, costly_count;         /* (level, quotes) of levels opened after quotes */
};

static int open_level (struct nesting *s) {
  s->levels++;
  s->depth += 1 + s->quotes;
  if (s->quotes > 0) {
    if (!s->costly && !(s->costly = malloc(2 * sizeof(long) * (s->limit + 1))))
      return 0;
    s->costly[2 * s->costly_count] = s->levels;
    s->costly[2 * s->costly_count + 1] = s->quotes;
    s->costly_count++;
  }
  s->quotes = 0;
  return s->depth <= s->limit;
}

static void close_level (struct nesting *s) {
  s->depth--;
  if (s->costly_count > 0 && s->costly[2 * (s->costly_count - 1)] == s->levels) {
    s->costly_count--;
    s->depth -= s->costly[2 * s->costly_count + 1];
  }
  s->levels--;
  s->quotes = 0;
}

static int delimiter (unsigned char c) {
  return c <= ' ' || strchr("()[]\";'`,|", c) != NULL;
}

/* The end of the string or |symbol| that starts at p (its quote), or of
 * the text when it is not closed. */
static const unsigned char *skip_quoted (const unsigned char *p,
                                         const unsigned char *end) {
  unsigned char q = *p++;
  for ( ; p < end && *p != q; p++)
    if (*p == '\\') p++;
  return p < end ? p + 1 : end;
}

static const unsigned char *skip_block_comment (const unsigned char *p,
                                                const unsigned char *end) {
  long open = 0;
  for ( ; p + 1 < end; p++) {
    if (p[0] == '#' && p[1] == '|') open++, p++;
    else if (p[0] == '|' && p[1] == '#' && --open == 0) return p + 2;
  }
  return end;
}

/* What follows a #: a character, a block comment, a datum comment (whose
 * datum is scanned as any other: the reader reads it), a label (sets
 * *label), or anything else, stepped over as an atom's start. */
static const unsigned char *after_hash (const unsigned char *p,
                                        const unsigned char *end, int *label) {
  const unsigned char *q = p + 1;
  if (q < end && *q == '\\') return q + 2 <= end ? q + 2 : end;
  if (q < end && *q == '|') return skip_block_comment(p, end);
  if (q < end && *q == ';') return q + 1;
  while (q < end && *q >= '0' && *q <= '9') q++;
  if (q > p + 1 && q < end && (*q == '=' || *q == '#')) *label = 1;
  return p + 1;
}

/* 1 when the text nests at most limit deep and has no label, else 0. */
static int nests_within (const unsigned char *p, const unsigned char *end,
                         long limit) {
  struct nesting s = {0, limit, 0, 0, NULL, 0};
  int ok = 1, label = 0;
  while (ok && !label && p < end) {
    unsigned char c = *p;
    if (c == '(' || c == '[') ok = open_level(&s), p++;
    else if (c == ')' || c == ']') close_level(&s), p++;
    else if (c == '"' || c == '|') p = skip_quoted(p, end), s.quotes = 0;
    else if (c == ';') { while (p < end && *p != '\n') p++; }
    else if (c == '\'' || c == '`' || c == ',') {
      ok = ++s.quotes + s.depth <= limit;
      p += (c == ',' && p + 1 < end && p[1] == '@') ? 2 : 1;
    }
    else if (c == '#') p = after_hash(p, end, &label);
    else if (c <= ' ') p++;
    else { while (p < end && !delimiter(*p)) p++; s.quotes = 0; }
  }
  free(s.costly);
  return ok && !label;
}

/* (nests-within? string limit): whether the text of string, of size
 * bytes, read as a datum, nests at most limit deep and has no datum label
 * (see Nesting). */
static int nests_within_text (const char *text, long size, long limit) {
  const unsigned char *p = (const unsigned char *)text;
  return nests_within(p, p + size, limit);
}
