;;> Code that travels: sendable closures, abandoning a call, and the
;;> sandbox where received code runs.

(define-library (murdoch code)
  (export abandon-thread! forget-abandoned! abandoned? check-not-abandoned
          abandoned-error? despite-abandonment with-wake-on-abandon
          make-lab-environment make-repl-environment check-lab-code
          visible-names nearest-name at-form-line make-guarded-thread
          make-logged-thread call-in-sandbox flush-call-ports!
          sandbox-parameter! set-sandbox-ports! sendable-lambda sendable-define
          encode made-by! make-decoder send-error? abridged set-value-limits!
          make-proxy-ref proxy-ref-uid proxy-ref-id make-proxy-procedure
          proxy-procedure-ref)
  (import (murdoch code abandon) (murdoch code sandbox) (murdoch code sendable)))
