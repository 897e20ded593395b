(define-library (murdoch remote)
  (export aspace? aspace-uid aspace-host aspace-port make-aspace
          local-aspace local-aspace-uid aspace-started-at uid->aspace known-uids
          learn-aspace! live-uids current-lab lab-environment
          remote-run! remote-apply remote-timeout set-remote-timeout!
          remote-apply-all remote-run-all! broadcast-apply broadcast-run!
          delivery-mode
          remote-error? remote-error-uid remote-error-message
          remote-timeout-error? remote-unreachable-error? remote-raised-error?
          remote-protocol-error?
          encap release-proxy! start-aspace!
          var-ref var-set! display-remote undo-on-raise with-lock)
  (import (scheme base) (scheme write) (scheme char)
          (scheme time)
          (srfi 1) (srfi 18) (srfi 69)
          (rename (only (chibi) read) (read read-datum))
          (only (chibi) call-with-output-string make-exception exception? string-size
                exception-kind exception-irritants
                strip-syntactic-closures)
          (only (chibi filesystem) open-input-file-descriptor
                open-output-file-descriptor)
          (chibi net) (only (chibi string) string-prefix?)
          (murdoch scheduler) (murdoch abandon) (murdoch connect) (murdoch multicast) (murdoch log) (murdoch netstring) (murdoch hmac) (murdoch sendable) (murdoch sandbox) (murdoch lab))
  (include "remote.scm" "multicast.scm"))
