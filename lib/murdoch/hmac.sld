;;> \procedure{(hmac-sha256 key message)}
;;> HMAC-SHA256 of \var{message} under \var{key}, each a bytevector or a
;;> string (its UTF-8 bytes), as a lowercase hex string.  The body is
;;> lib/hmac.c, built into lib/murdoch/hmac.so by \scheme{make native}.

(define-library (murdoch hmac)
  (export hmac-sha256 make-hmac-sha256)
  (import (scheme base))
  (include-shared "hmac")
  (include "../hmac.scm"))
