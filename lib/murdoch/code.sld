;;> Code that travels: sendable closures, abandoning a call, and the
;;> sandbox where received code runs.
;;> Its members are each a library of their own in code/.

(define-library (murdoch code)
  (export abandon-thread! forget-abandoned! abandoned? check-not-abandoned
          abandoned-error? despite-abandonment with-wake-on-abandon make-lab-environment
          make-repl-environment lab-code-files check-lab-code visible-names nearest-name
          at-form-line guarded-set! guarded-thread-terminate!
          make-guarded-thread make-logged-thread sized-make-vector sized-make-string
          sized-make-bytevector sized-make-list sized-list-tabulate sized-iota
          sized-read-bytevector sized-expt call-in-sandbox flush-call-ports!
          sandbox-parameter! set-sandbox-ports! sendable-lambda sendable-define
          sendable-procedure? encode made-by!
          make-decoder send-error? abridged set-value-limits! make-proxy-ref proxy-ref?
          proxy-ref-uid proxy-ref-id make-proxy-procedure proxy-procedure-ref)
  (import (murdoch code abandon) (murdoch code sandbox) (murdoch code sendable)))
