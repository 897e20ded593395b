/* The C of (murdoch sendable): the look at a value that decides whether
 * it stands for itself on the wire (sendable.scm, "plain?"), and the one
 * list of the atoms that do, which encode's walk asks of each element
 * too (plain-atom?).  Every call's arguments and every answer's value are
 * looked at so, at both ends; in Scheme the look cost about a third of a
 * microsecond a pair, a microsecond and more of each message. */

#include <chibi/eval.h>

static int plain_atom (sexp x) {
  return sexp_numberp(x) || sexp_stringp(x) || sexp_symbolp(x)
    || sexp_charp(x) || sexp_booleanp(x) || sexp_nullp(x) || sexp_bytesp(x);
}

/* The budget left after looking through x, or -1 when x is not plain or
 * the budget of pairs or the depth runs out: down cdrs by iteration, into
 * cars by recursion, at most max_depth deep. */
static long plain_pairs (sexp x, long budget, long depth, long max_depth) {
  for (;;) {
    if (!sexp_pairp(x))
      return plain_atom(x) ? budget : -1;
    if (budget <= 0 || depth >= max_depth)
      return -1;
    budget = plain_pairs(sexp_car(x), budget - 1, depth + 1, max_depth);
    if (budget < 0)
      return -1;
    x = sexp_cdr(x);
  }
}

static sexp plain_atom_p (sexp ctx, sexp self, sexp_sint_t n, sexp x) {
  return sexp_make_boolean(plain_atom(x));
}

static sexp plain_p (sexp ctx, sexp self, sexp_sint_t n,
                     sexp x, sexp budget, sexp max_depth) {
  if (!sexp_fixnump(budget))
    return sexp_type_exception(ctx, self, SEXP_FIXNUM, budget);
  if (!sexp_fixnump(max_depth))
    return sexp_type_exception(ctx, self, SEXP_FIXNUM, max_depth);
  return sexp_make_boolean(plain_pairs(x, sexp_unbox_fixnum(budget), 0,
                                       sexp_unbox_fixnum(max_depth)) >= 0);
}

sexp sexp_init_library (sexp ctx, sexp self, sexp_sint_t n, sexp env,
                        const char *version, const sexp_abi_identifier_t abi) {
  if (!(sexp_version_compatible(ctx, version, sexp_version)
        && sexp_abi_compatible(ctx, abi, SEXP_ABI_IDENTIFIER)))
    return SEXP_ABI_ERROR;
  sexp_define_foreign(ctx, env, "plain-within?", 3, plain_p);
  sexp_define_foreign(ctx, env, "plain-atom?", 1, plain_atom_p);
  return SEXP_VOID;
}
