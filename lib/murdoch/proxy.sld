;;> encap's proxies: procedures applied where they were made.

(define-library (murdoch proxy)
  (export encap release-proxy! decode-proxy)
  (import (scheme base) (srfi 18) (srfi 69)
          (murdoch wait) (murdoch sendable) (murdoch aspace) (murdoch call))
  (include "proxy.scm"))
