;;> remote-run! and remote-apply, their -all forms, and the waiting for
;;> answers that delivery's datagram calls share.

(define-library (murdoch remote call)
  (export remote-run! remote-apply remote-apply-all remote-run-all!
          outcome-uid outcome-ok? outcome-value
          new-call call? call-kind call-proc call-args call-proc-code call-args-code
          call-seconds call-all apply-each make-result result? result-uid result-ok? result-value
          encode-arguments send-all local-call capture
          capture-each await-answers answer-value no-answer datagram-others
          expect-answers! forget-answers!
          take-datagram-answer! prober)
  (import (scheme base) (srfi 1) (srfi 18) (srfi 69) (murdoch sys)
          (murdoch wire) (murdoch code) (murdoch remote aspace)
          (murdoch remote connection) (murdoch remote worker))
  (include "call.scm"))
