/*  process-name.c -- the C of (murdoch process-name)
 *
 *  An address space runs as Chibi through the private libc's loader, so
 *  ps and top would show every one as ld-linux-x86-64.so.2.  The kernel's
 *  name of the process (its comm, at most 15 bytes) is set here instead.
 */

#include <chibi/eval.h>
#include <string.h>
#include <sys/prctl.h>

/* (set-process-name! NAME): the process's name as ps shows it, cut to 15
 * bytes; #t, or #f when the kernel refused. */
static sexp set_process_name (sexp ctx, sexp self, sexp_sint_t n, sexp name) {
  char comm[16];
  if (!sexp_stringp(name))
    return sexp_type_exception(ctx, self, SEXP_STRING, name);
  strncpy(comm, sexp_string_data(name), sizeof comm - 1);
  comm[sizeof comm - 1] = '\0';
  return sexp_make_boolean(prctl(PR_SET_NAME, comm, 0, 0, 0) == 0);
}

sexp sexp_init_library (sexp ctx, sexp self, sexp_sint_t n, sexp env,
                        const char *version, const sexp_abi_identifier_t abi) {
  if (!(sexp_version_compatible(ctx, version, sexp_version)
        && sexp_abi_compatible(ctx, abi, SEXP_ABI_IDENTIFIER)))
    return SEXP_ABI_ERROR;
  sexp_define_foreign(ctx, env, "set-process-name!", 1, set_process_name);
  return SEXP_VOID;
}
