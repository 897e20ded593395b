;;> A TCP connect that gives up at a timeout: \scheme{open-connection},
;;> the non-blocking replacement of (chibi net)'s \scheme{open-net-io}.
;;> The C is lib/connect.c, built into lib/murdoch/connect.so by
;;> \scheme{make native}; the waiting is lib/connect.scm.

(define-library (murdoch connect)
  (export open-connection)
  (import (scheme base) (srfi 18) (only (murdoch scheduler) monotonic-seconds))
  (include-shared "connect")
  (include "../connect.scm"))
