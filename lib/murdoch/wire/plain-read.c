/*  plain-read.c -- reading a message's text in C, part of netstring.stub
 *
 *  Every frame's message was read by Chibi's `read' from a string port
 *  after the nesting scan: about 17,800 instructions for a request's call
 *  of 100 bytes (docs/speed.md), a character at a time through the port,
 *  and a 4 KB port buffer of garbage a frame.  What our writer puts on
 *  the wire is nearly always plain: lists, dotted pairs, vectors, symbols,
 *  small integers, strings, #t and #f, in ASCII.  This reads that straight
 *  from the string's bytes, nesting counted as the scan counts it, and
 *  answers `other' for anything else: a number that is not a small
 *  integer, a character, a string escape but \\ \" \n \t, a quote, a
 *  comment, |symbol|, a label, a byte past ASCII, text nesting past the
 *  limit or not one datum.  The caller reads those as before, where the
 *  scan and the reader say what is wrong.  So what this answers is what
 *  `read' would, or nothing.
 */

/* The text being read, and the answer that it is not plain. */
struct plain {
  const unsigned char *p, *end;
  sexp other;
};

static int plain_space (unsigned char c) {
  return c == ' ' || c == '\n' || c == '\t' || c == '\r';
}

/* Where `read' ends an atom (sexp_is_separator), and the text. */
static int plain_delimited (struct plain *s) {
  return s->p == s->end || plain_space(*s->p)
    || *s->p == '(' || *s->p == ')' || *s->p == '"';
}

/* The bytes of a plain atom: letters, digits and R7RS's special initials. */
static const unsigned char symbol_bytes[128] = {
  ['!'] = 1, ['$'] = 1, ['%'] = 1, ['&'] = 1, ['*'] = 1, ['/'] = 1, [':'] = 1,
  ['<'] = 1, ['='] = 1, ['>'] = 1, ['?'] = 1, ['^'] = 1, ['_'] = 1, ['~'] = 1,
  ['+'] = 1, ['-'] = 1, ['.'] = 1, ['@'] = 1,
  ['0'] = 1, ['1'] = 1, ['2'] = 1, ['3'] = 1, ['4'] = 1, ['5'] = 1, ['6'] = 1,
  ['7'] = 1, ['8'] = 1, ['9'] = 1,
  ['A'] = 1, ['B'] = 1, ['C'] = 1, ['D'] = 1, ['E'] = 1, ['F'] = 1, ['G'] = 1,
  ['H'] = 1, ['I'] = 1, ['J'] = 1, ['K'] = 1, ['L'] = 1, ['M'] = 1, ['N'] = 1,
  ['O'] = 1, ['P'] = 1, ['Q'] = 1, ['R'] = 1, ['S'] = 1, ['T'] = 1, ['U'] = 1,
  ['V'] = 1, ['W'] = 1, ['X'] = 1, ['Y'] = 1, ['Z'] = 1,
  ['a'] = 1, ['b'] = 1, ['c'] = 1, ['d'] = 1, ['e'] = 1, ['f'] = 1, ['g'] = 1,
  ['h'] = 1, ['i'] = 1, ['j'] = 1, ['k'] = 1, ['l'] = 1, ['m'] = 1, ['n'] = 1,
  ['o'] = 1, ['p'] = 1, ['q'] = 1, ['r'] = 1, ['s'] = 1, ['t'] = 1, ['u'] = 1,
  ['v'] = 1, ['w'] = 1, ['x'] = 1, ['y'] = 1, ['z'] = 1
};

static int symbol_byte (unsigned char c) {
  return c < 128 && symbol_bytes[c];
}

static void skip_space (struct plain *s) {
  while (s->p < s->end && plain_space(*s->p)) s->p++;
}

static sexp plain_datum (sexp ctx, struct plain *s, long depth);

/* The symbols read lately, by a hash of their names.  Chibi's intern
 * hashes the name and walks a bucket of its table, a few hundred
 * instructions a symbol, and a frame has several, the same in every
 * call.  Chibi's table holds each symbol for good (its collector marks
 * the table), so a symbol kept here is never freed under us. */
#define KNOWN_SYMBOLS 512
#define KNOWN_SYMBOL_BYTES 32
static struct known_symbol {
  sexp symbol;
  long size;
  char name[KNOWN_SYMBOL_BYTES];
} known_symbols[KNOWN_SYMBOLS];

static int known_as (struct known_symbol *k, const char *name, long size) {
  return k->symbol && k->size == size && memcmp(k->name, name, size) == 0;
}

/* Each name has two places, for names whose first place another took. */
static sexp plain_symbol (sexp ctx, const char *name, long size) {
  unsigned long h = 2166136261u;
  long i;
  struct known_symbol *a, *b;
  sexp sym;
  for (i = 0; i < size; i++) h = (h ^ (unsigned char)name[i]) * 16777619u;
  a = &known_symbols[h % KNOWN_SYMBOLS];
  b = &known_symbols[(h >> 16) % KNOWN_SYMBOLS];
  if (known_as(a, name, size)) return a->symbol;
  if (known_as(b, name, size)) return b->symbol;
  sym = sexp_intern(ctx, name, size);
  if (!sexp_exceptionp(sym) && size <= KNOWN_SYMBOL_BYTES) {
    if (a->symbol) a = b;
    a->symbol = sym;
    a->size = size;
    memcpy(a->name, name, size);
  }
  return sym;
}

/* An integer of at most 17 digits, a fixnum on any Chibi; a symbol that
 * cannot be taken for a number; else other. */
static sexp plain_atom (sexp ctx, struct plain *s) {
  const unsigned char *start = s->p, *digits;
  sexp_sint_t n = 0;
  while (s->p < s->end && symbol_byte(*s->p)) s->p++;
  if (!plain_delimited(s)) return s->other;
  digits = start + (*start == '-' || *start == '+');
  if (digits < s->p && *digits >= '0' && *digits <= '9') {
    const unsigned char *q;
    if (s->p - digits > 17) return s->other;
    for (q = digits; q < s->p; q++) {
      if (*q < '0' || *q > '9') return s->other;
      n = n * 10 + (*q - '0');
    }
    return sexp_make_fixnum(*start == '-' ? -n : n);
  }
  /* .5, the lone dot, +i, -inf.0, +.5 ... are numbers or syntax to
   * read; + and - alone are symbols. */
  if (*start == '.' || ((*start == '+' || *start == '-') && start + 1 < s->p))
    return s->other;
  return plain_symbol(ctx, (const char *)start, s->p - start);
}

static sexp plain_string (sexp ctx, struct plain *s) {
  const unsigned char *start = ++s->p;
  char *bytes;
  long n = 0;
  sexp res;
  int escaped = 0;
  for ( ; s->p < s->end && *s->p != '"'; s->p++) {
    if (*s->p >= 0x80) return s->other;
    if (*s->p == '\\') {
      /* strchr finds a NUL byte too: the string's own end. */
      if (++s->p == s->end || !*s->p || !strchr("\\\"nt", *s->p)) return s->other;
      escaped = 1;
    }
  }
  if (s->p == s->end) return s->other;
  s->p++;
  if (!escaped)
    return sexp_c_string(ctx, (const char *)start, s->p - 1 - start);
  if (!(bytes = malloc(s->p - start))) return s->other;
  for ( ; start < s->p - 1; start++) {
    if (*start == '\\') {
      start++;
      bytes[n++] = *start == 'n' ? '\n' : *start == 't' ? '\t' : *start;
    } else bytes[n++] = *start;
  }
  res = sexp_c_string(ctx, bytes, n);
  free(bytes);
  return res;
}

/* The elements up to the closing paren, after the opening one: a list,
 * dotted when ". DATUM" ends it, or other. */
static sexp plain_elements (sexp ctx, struct plain *s, long depth) {
  sexp last;
  sexp_gc_var2(acc, x);
  sexp_gc_preserve2(ctx, acc, x);
  acc = SEXP_NULL;
  for (;;) {
    skip_space(s);
    if (s->p == s->end) { acc = s->other; break; }
    if (*s->p == ')') {
      s->p++;
      acc = sexp_nreverse(ctx, acc);
      break;
    }
    if (*s->p == '.' && s->p + 1 < s->end && plain_space(s->p[1])
        && sexp_pairp(acc)) {
      s->p++;
      x = plain_datum(ctx, s, depth);
      skip_space(s);
      if (x == s->other || s->p == s->end || *s->p != ')') {
        acc = s->other;
        break;
      }
      s->p++;
      last = acc;                       /* the pair that ends the list */
      acc = sexp_nreverse(ctx, acc);
      sexp_cdr(last) = x;
      break;
    }
    x = plain_datum(ctx, s, depth);
    if (x == s->other || sexp_exceptionp(x)) { acc = x; break; }
    acc = sexp_cons(ctx, x, acc);
  }
  sexp_gc_release2(ctx);
  return acc;
}

/* A vector's elements, after its "#(". */
static sexp plain_vector (sexp ctx, struct plain *s, long depth) {
  sexp_gc_var1(ls);
  sexp_gc_preserve1(ctx, ls);
  ls = plain_elements(ctx, s, depth);
  if (ls != s->other && !sexp_exceptionp(ls))
    ls = sexp_listp(ctx, ls) == SEXP_FALSE ? s->other : sexp_list_to_vector(ctx, ls);
  sexp_gc_release1(ctx);
  return ls;
}

/* One datum at s->p, nested depth levels in: lists and vectors count one
 * each, as the nesting scan counts them. */
static sexp plain_datum (sexp ctx, struct plain *s, long depth) {
  skip_space(s);
  if (s->p == s->end) return s->other;
  switch (*s->p) {
  case '(':
    if (depth == 0) return s->other;
    s->p++;
    return plain_elements(ctx, s, depth - 1);
  case '"':
    return plain_string(ctx, s);
  case '#':
    if (s->p + 1 < s->end && s->p[1] == '(') {
      if (depth == 0) return s->other;
      s->p += 2;
      return plain_vector(ctx, s, depth - 1);
    }
    if (s->p + 1 < s->end && (s->p[1] == 't' || s->p[1] == 'f')) {
      s->p += 2;
      if (!plain_delimited(s)) return s->other;
      return s->p[-1] == 't' ? SEXP_TRUE : SEXP_FALSE;
    }
    return s->other;
  default:
    return symbol_byte(*s->p) ? plain_atom(ctx, s) : s->other;
  }
}

/* (plain-message string limit other): the one datum that string's text,
 * of size bytes, holds, read as `read' would, when it is plain and nests
 * at most limit deep; else other. */
static sexp plain_message (sexp ctx, const char *text, long size, long limit,
                           sexp other) {
  struct plain s;
  sexp res;
  s.p = (const unsigned char *)text;
  s.end = s.p + size;
  s.other = other;
  res = plain_datum(ctx, &s, limit);
  if (res == other || sexp_exceptionp(res)) return res;
  return s.p == s.end ? res : other;    /* as parse-message refuses more */
}

/* Whether x is a proper list, as list? says: a cycle is not one. */
static int proper_list (sexp x) {
  sexp slow = x;
  while (sexp_pairp(x) && sexp_pairp(sexp_cdr(x))) {
    x = sexp_cddr(x);
    slow = sexp_cdr(slow);
    if (x == slow) return 0;
  }
  return sexp_nullp(sexp_pairp(x) ? sexp_cdr(x) : x);
}

/* Whether x passes check, a field's check from frame.scm's check-codes:
 * 0 anything, 1 an exact integer, 2 a symbol, 3 a string, 4 a list, 5 a
 * pair, or a list of the symbols x may be. */
static int field_passes (sexp check, sexp x) {
  if (sexp_pairp(check)) {
    for (; sexp_pairp(check); check = sexp_cdr(check))
      if (sexp_car(check) == x) return 1;
    return 0;
  }
  switch (sexp_unbox_fixnum(check)) {
  case 0: return 1;
  case 1: return sexp_exact_integerp(x);
  case 2: return sexp_symbolp(x);
  case 3: return sexp_stringp(x);
  case 4: return proper_list(x);
  case 5: return sexp_pairp(x);
  default: return 0;
  }
}

/* (fields-pass? values checks): whether values holds one field for each
 * of checks, each passing it (frame.scm's check-message). */
static sexp fields_pass (sexp ctx, sexp values, sexp checks) {
  for (; sexp_pairp(checks); checks = sexp_cdr(checks), values = sexp_cdr(values))
    if (!sexp_pairp(values) || !field_passes(sexp_car(checks), sexp_car(values)))
      return SEXP_FALSE;
  return sexp_make_boolean(sexp_nullp(values));
}
