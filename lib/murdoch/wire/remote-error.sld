;;> The family of errors a remote call raises, with a predicate for each
;;> kind; the wire's own faults are its protocol kind.

(define-library (murdoch wire remote-error)
  (export remote-error protocol-fail error-message error-message-naming
          remote-error? remote-error-uid remote-error-message
          remote-timeout-error? remote-unreachable-error? remote-raised-error?
          remote-protocol-error?)
  (import (scheme base) (scheme write) (srfi 18)
          (only (chibi) call-with-output-string make-exception exception?
                exception-kind exception-irritants strip-syntactic-closures)
          (only (murdoch sys) stack-guard-tripped? condition-message))
  (include "remote-error.scm"))
