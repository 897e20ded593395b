;;> The sandbox: the environment received code runs in, and the dynamic
;;> extent each received call runs in.
(define-library (murdoch sandbox)
  (export make-lab-environment make-repl-environment lab-code-files
          guarded-set! guarded-thread-terminate! make-guarded-thread
          call-in-sandbox sandbox-parameter! set-sandbox-ports!)
  (import (scheme base) (scheme write) (scheme eval) (scheme file)
          (srfi 1) (srfi 18) (srfi 69)
          (only (chibi) env-parent identifier? identifier->symbol port-open?
                thread-parameters thread-parameters-set!
                make-syntactic-closure)
          (only (chibi ast) env-cell)
          (only (chibi io) make-custom-output-port make-null-input-port)
          (only (meta) mutable-environment)
          (murdoch lab))
  (include "sandbox.scm"))
