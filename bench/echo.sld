;;> The bare Chibi echo server that the benches measure Murdoch against.
;;> It imports only what it uses: an echo server that imported (murdoch
;;> testing) took four times as long to start (bench/echo-server.scm).

(define-library (bench echo)
  (export echo-connection)
  (import (scheme base) (srfi 18) (srfi 151) (chibi net) (chibi filesystem)
          (murdoch wire netstring))
  (include "echo.scm"))
