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
 * session).  A place is (PAIR IN-CAR? . DEPTH): the vector is PAIR's car,
 * or its cdr, and is decoded at DEPTH, as the Scheme walk had it. */

/* Conses the place of the vector in p's car (in_car) or cdr onto *result;
 * 0 when the heap is out. */
static int add_place (sexp ctx, sexp p, int in_car, long depth,
                      sexp *place, sexp *result) {
  *place = sexp_cons(ctx, in_car ? SEXP_TRUE : SEXP_FALSE, sexp_make_fixnum(depth));
  if (sexp_exceptionp(*place)) return 0;
  *place = sexp_cons(ctx, p, *place);
  if (sexp_exceptionp(*place)) return 0;
  *result = sexp_cons(ctx, *place, *result);
  return !sexp_exceptionp(*result);
}

/* Walks pair p, decoded at depth (its elements one deeper): down cdrs by
 * iteration, into cars by recursion; -1 past max_depth, 0 when the heap
 * is out, else 1. */
static int walk_places (sexp ctx, sexp p, long depth, long max_depth,
                        sexp *place, sexp *result) {
  int ok;
  if (depth + 1 > max_depth) return -1;
  for (;;) {
    if (sexp_pairp(sexp_car(p))) {
      if ((ok = walk_places(ctx, sexp_car(p), depth + 1, max_depth, place, result)) < 1)
        return ok;
    } else if (sexp_vectorp(sexp_car(p))) {
      if (!add_place(ctx, p, 1, depth + 1, place, result)) return 0;
    }
    if (sexp_pairp(sexp_cdr(p))) {
      p = sexp_cdr(p);
    } else {
      if (sexp_vectorp(sexp_cdr(p)) && !add_place(ctx, p, 0, depth + 1, place, result))
        return 0;
      return 1;
    }
  }
}

/* (tagged-places pair depth max-depth): the places of pair's tagged
 * vectors in the walk's order, or #f when it nests past max_depth. */
static sexp tagged_places (sexp ctx, sexp self, sexp p, long depth, long max_depth) {
  int ok;
  sexp_gc_var2(place, result);
  if (!sexp_pairp(p)) return sexp_type_exception(ctx, self, SEXP_PAIR, p);
  sexp_gc_preserve2(ctx, place, result);
  result = SEXP_NULL;
  ok = walk_places(ctx, p, depth, max_depth, &place, &result);
  if (ok < 0) result = SEXP_FALSE;
  else if (ok == 0) result = sexp_global(ctx, SEXP_G_OOM_ERROR);
  else result = sexp_nreverse(ctx, result);
  sexp_gc_release2(ctx);
  return result;
}
