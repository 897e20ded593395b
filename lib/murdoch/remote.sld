;;> The remote layer as one import: address spaces, remote calls (thesis
;;> §3.3.2), their errors, proxies, delivery, and start-aspace!.

(define-library (murdoch remote)
  (export aspace? aspace-uid aspace-host aspace-port local-aspace
          local-aspace-uid aspace-started-at uid->aspace known-uids live-uids
          live-aspace remote-run! remote-apply remote-timeout
          remote-apply-all remote-run-all! outcome-uid
          outcome-ok? outcome-value call-all apply-each broadcast-apply broadcast-run!
          make-result result-uid result-ok? result-value delivery-mode
          remote-error? remote-error-uid remote-error-message
          remote-timeout-error? remote-unreachable-error? remote-raised-error?
          remote-protocol-error? encap release-proxy! start-aspace!
          hand-over-connection! release-call! var-ref var-set! display-remote undo-on-raise run-logged
          with-lock screen-calls!)
  (import (scheme base) (scheme write) (murdoch sys) (murdoch wire) (murdoch lab)
          (murdoch code) (murdoch remote aspace) (murdoch remote worker)
          (murdoch remote call) (murdoch remote serve) (murdoch remote group)
          (murdoch remote proxy) (murdoch remote delivery)
          (only (murdoch remote connection) open-connections!))
  (include "remote.scm"))
