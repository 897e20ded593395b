/* call-bindings.c -- the C of (murdoch code sandbox), which sandbox.stub binds
 *
 * A received call's own binding of each of the sandbox's parameters, its
 * value the one the thread sees now (sandbox.scm, call-in-sandbox).  In
 * Scheme, reading each parameter and consing its pair took 9,000 of the
 * 114,000 instructions a receiver spends on a request (docs/speed.md,
 * "The receivers' share"). */

#include <chibi/eval.h>

/* bindings with a fresh (parameter . value) pair in front of it for each
 * of parameters, which are parameter objects: the first the innermost. */
static sexp fresh_bindings (sexp ctx, sexp self, sexp parameters, sexp bindings) {
  sexp ls;
  sexp_gc_var2(result, binding);
  for (ls = parameters; sexp_pairp(ls); ls = sexp_cdr(ls))
    if (!sexp_opcodep(sexp_car(ls)))
      return sexp_type_exception(ctx, self, SEXP_OPCODE, sexp_car(ls));
  sexp_gc_preserve2(ctx, result, binding);
  result = bindings;
  for (ls = parameters; sexp_pairp(ls); ls = sexp_cdr(ls)) {
    binding = sexp_cons(ctx, sexp_car(ls), sexp_parameter_ref(ctx, sexp_car(ls)));
    result = sexp_cons(ctx, binding, result);
  }
  sexp_gc_release2(ctx);
  return result;
}
