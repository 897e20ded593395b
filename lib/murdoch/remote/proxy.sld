;;> encap's proxies: procedures applied where they were made.

(define-library (murdoch remote proxy)
  (export encap release-proxy! decode-proxy)
  (import (scheme base) (srfi 18) (srfi 69) (murdoch sys) (murdoch code)
          (murdoch remote aspace) (murdoch remote call))
  (include "proxy.scm"))
