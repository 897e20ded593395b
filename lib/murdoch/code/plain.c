/* plain.c -- the C of (murdoch code sendable), which sendable.stub binds
 *
 * The look at a value that decides whether it stands for itself on the
 * wire (sendable.scm, "plain?"), and the one list of the atoms that do,
 * which encode's walk asks of each element too (plain-atom?).  Every
 * call's arguments and every answer's value are looked at so, at both
 * ends; in Scheme the look cost about a third of a microsecond a pair, a
 * microsecond and more of each message. */

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

/* Whether x is plain within budget pairs and max_depth levels. */
static int plain_within (sexp x, long budget, long max_depth) {
  return plain_pairs(x, budget, 0, max_depth) >= 0;
}
