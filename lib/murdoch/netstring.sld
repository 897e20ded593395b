(define-library (murdoch netstring)
  (export read-netstring write-netstring
          netstring-error? netstring-error-message)
  (import (scheme base))
  (include "../netstring.scm"))
