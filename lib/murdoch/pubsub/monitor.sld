;;> Monitors (A.6): idle while the load is low, untethered off the charger;
;;> and an address space's first subscriptions, from its lab clause (A.2).

(define-library (murdoch pubsub monitor)
  (export get-system-load load-monitor battery-monitor
          battery-charging battery-low load-threshold
          set-battery-charging! set-battery-low! set-load-threshold!
          initialize-subscriptions!)
  (import (only (murdoch code) make-logged-thread)
          (scheme base) (scheme read) (scheme file) (srfi 1) (srfi 18) (murdoch sys)
          (murdoch lab) (murdoch remote) (murdoch robot) (murdoch pubsub messaging))
  (include "monitor.scm"))
