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

/* The decoder's walk (sendable.scm, make-decoder): where in the pairs of
 * x, a value fresh from a frame, its tagged vectors sit, for the Scheme
 * to rebuild in place.  In Scheme the walk was a third of decoding a
 * request's arguments (docs/speed.md, "The receivers' share", sixth
 * session).  The places come in one vector, two slots a place: the pair
 * that holds the tagged vector, and DEPTH * 2 + 1 when it is the pair's
 * car, DEPTH * 2 when its cdr, DEPTH the level it is decoded at, as the
 * Scheme walk had it.  Plain data, most values, makes nothing. */

/* Walks pair p, decoded at depth (its elements one deeper): down cdrs by
 * iteration, into cars by recursion.  Counts the places in *n, and when
 * places is a vector puts them there too.  0 past max_depth, else 1. */
static int walk_places (sexp p, long depth, long max_depth, sexp places, long *n) {
  if (depth + 1 > max_depth) return 0;
  for (;;) {
    if (sexp_pairp(sexp_car(p))) {
      if (!walk_places(sexp_car(p), depth + 1, max_depth, places, n)) return 0;
    } else if (sexp_vectorp(sexp_car(p))) {
      if (sexp_vectorp(places)) {
        sexp_vector_set(places, sexp_make_fixnum(2 * *n), p);
        sexp_vector_set(places, sexp_make_fixnum(2 * *n + 1),
                        sexp_make_fixnum(2 * (depth + 1) + 1));
      }
      ++*n;
    }
    if (sexp_pairp(sexp_cdr(p))) {
      p = sexp_cdr(p);
    } else {
      if (sexp_vectorp(sexp_cdr(p))) {
        if (sexp_vectorp(places)) {
          sexp_vector_set(places, sexp_make_fixnum(2 * *n), p);
          sexp_vector_set(places, sexp_make_fixnum(2 * *n + 1),
                          sexp_make_fixnum(2 * (depth + 1)));
        }
        ++*n;
      }
      return 1;
    }
  }
}

/* (tagged-places pair depth max-depth): the places of pair's tagged
 * vectors in the walk's order, #f when none, or the symbol too-deep when
 * pair nests past max_depth.  Two walks, the first to count: a walk is
 * cheaper than the pairs a list of places would make. */
static sexp tagged_places (sexp ctx, sexp self, sexp p, long depth, long max_depth) {
  long n = 0;
  sexp places;
  if (!sexp_pairp(p)) return sexp_type_exception(ctx, self, SEXP_PAIR, p);
  if (!walk_places(p, depth, max_depth, SEXP_FALSE, &n))
    return sexp_intern(ctx, "too-deep", -1);
  if (n == 0) return SEXP_FALSE;
  places = sexp_make_vector(ctx, sexp_make_fixnum(2 * n), SEXP_FALSE);
  if (sexp_exceptionp(places)) return places;
  n = 0;
  walk_places(p, depth, max_depth, places, &n);
  return places;
}
