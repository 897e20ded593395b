;;> \procedure{(hmac-sha256 key part ...)}
;;> HMAC-SHA256 under \var{key} of the message made of the \var{part}s one
;;> after the other, as a lowercase hex string.  The key and each part are
;;> a bytevector or a string (its UTF-8 bytes); a part may also be a
;;> fixnum, which stands for its decimal digits.  The body is
;;> lib/hmac.c, built into lib/murdoch/hmac.so by \scheme{make native}.

(define-library (murdoch hmac)
  (export hmac-sha256 make-hmac-sha256)
  (import (scheme base))
  (include-shared "hmac")
  (include "../hmac.scm"))
