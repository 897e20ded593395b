;;> Publish/subscribe messaging (thesis §4.1, appendix A.8): subjects,
;;> publish, request, request-exclusive and its promises, leases.

(define-library (murdoch pubsub messaging)
  (export subscribe unsubscribe subscriptions topic-status set-topic-status!
          subscribe-remote unsubscribe-remote
          publish request request-exclusive request-non-exclusive
          request-components request-audience asked-ok? asked-value
          capability-layout check-subjects
          request-status subscription-statuses
          receive-publication receive-request receive-request-exclusive
          receive-request-non-exclusive receive-components start-leases!
          open-subscriber! offer-subjects! addressed-here?)
  (import (only (murdoch code) make-logged-thread) (scheme base) (srfi 1) (srfi 18)
          (murdoch sys) (murdoch lab) (murdoch remote)
          (only (murdoch wire) error-message))
  (include "messaging.scm" "receiving.scm"))
