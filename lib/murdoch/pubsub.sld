(define-library (murdoch pubsub)
  (export subscribe unsubscribe subscriptions topic-status set-topic-status!
          subscribe-remote unsubscribe-remote
          publish request request-exclusive request-non-exclusive
          capability-layout check-subjects
          request-status subscription-statuses
          receive-publication receive-request receive-request-exclusive
          receive-request-non-exclusive set-lease!
          get-system-load load-monitor battery-monitor
          *battery-charging* *battery-low* *load-threshold*
          set-battery-charging! set-battery-low! set-load-threshold!
          initialize-subscriptions!)
  (import (scheme base) (scheme read) (scheme file) (only (murdoch scheduler) monotonic-seconds)
          (srfi 1) (srfi 18)
          (murdoch log) (murdoch lab) (murdoch remote) (murdoch trip-client))
  (include "pubsub.scm"))
