;;> The sandbox: the environment received code runs in, and the dynamic
;;> extent each received call runs in.
(define-library (murdoch code sandbox)
  (export make-lab-environment make-repl-environment lab-code-files check-lab-code
          visible-names nearest-name at-form-line
          guarded-set! guarded-thread-terminate! make-guarded-thread
          make-logged-thread sized-make-vector sized-make-string
          sized-make-bytevector sized-make-list sized-list-tabulate
          sized-iota sized-read-bytevector sized-expt
          call-in-sandbox flush-call-ports! sandbox-parameter! set-sandbox-ports!)
  (import (scheme base) (scheme read) (scheme eval) (scheme file) (scheme inexact)
          (scheme write) (srfi 1) (srfi 18) (srfi 69)
          (only (chibi) env-parent identifier? identifier->symbol port-open?
                thread-parameters thread-parameters-set! make-syntactic-closure
                call-with-output-string warn-undefs env-exports)
          (only (chibi ast) env-cell)
          (only (chibi string) string-prefix?)
          (only (chibi edit-distance) find-nearest-edits edit-distance)
          (only (chibi io) make-custom-output-port make-null-input-port)
          (only (meta) mutable-environment) (murdoch sys)
          (only (murdoch wire) error-message) (murdoch lab))
  (include-shared "sandbox")
  (include "sandbox.scm"))
