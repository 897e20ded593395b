;;> Sendable procedures: Murdoch's lambda, closures that travel as
;;> S-expressions, with bounded depth and size.

(define-library (murdoch code sendable)
  (export sendable-lambda sendable-define sendable-procedure?
          encode make-decoder send-error? made-by! abridged set-value-limits!
          make-proxy-ref proxy-ref? proxy-ref-uid proxy-ref-id
          make-proxy-procedure proxy-procedure-ref)
  (import (scheme base) (scheme eval) (scheme write)
          (rename (only (scheme base) lambda define)
                  (lambda %lambda) (define %define))
          (rename (only (chibi) equal?) (equal? chibi-equal?))
          (only (chibi) er-macro-transformer make-syntactic-closure
                strip-syntactic-closures
                make-exception exception? exception-kind closure?)
          (chibi ast)
          (srfi 1) (srfi 18) (srfi 69) (only (murdoch sys) define-lean-record-type)
          (murdoch lab))
  (include-shared "sendable")
  (include "sendable.scm"))
