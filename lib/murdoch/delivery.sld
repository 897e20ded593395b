;;> Delivery: broadcast-apply and broadcast-run! reach every live address
;;> space, by one multicast datagram when the lab says so, else each in
;;> turn; beacons keep the live set without a registry.

(define-library (murdoch delivery)
  (export broadcast-apply broadcast-run! start-multicast! delivery-mode)
  (import (scheme base) (scheme write) (srfi 1) (srfi 18)
          (srfi 69)
          (only (chibi) call-with-output-string)
          (chibi net) (chibi match)
          (murdoch scheduler) (murdoch log) (murdoch wait) (murdoch abandon) (murdoch remote-error)
          (murdoch multicast) (murdoch frame) (murdoch lab) (murdoch sendable)
          (murdoch aspace) (murdoch worker) (murdoch connection)
          (murdoch call) (murdoch serve))
  (include "delivery.scm"))
