;;> Publish/subscribe messaging (appendix A.8): subjects, requests and
;;> their promises, and the monitors (A.6, A.2).

(define-library (murdoch pubsub)
  (export subscribe unsubscribe subscriptions topic-status set-topic-status!
          subscribe-remote unsubscribe-remote publish request request-exclusive
          request-non-exclusive request-components request-audience asked-ok? asked-value
          capability-layout check-subjects request-status subscription-statuses
          receive-publication receive-request receive-request-exclusive
          receive-request-non-exclusive receive-components
          offer-subjects! addressed-here? get-system-load load-monitor battery-monitor
          battery-charging battery-low load-threshold
          set-battery-charging! set-battery-low! set-load-threshold!
          open-subscriber! initialize-subscriptions!)
  (import (murdoch pubsub messaging) (murdoch pubsub monitor)))
