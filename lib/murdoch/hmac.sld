(define-library (murdoch hmac)
  (export hmac-sha256 make-hmac-sha256 hex->bytevector)
  (import (scheme base) (srfi 151) (chibi crypto sha2))
  (include "../hmac.scm"))
