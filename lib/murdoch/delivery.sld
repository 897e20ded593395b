;;> Delivery: broadcast-apply and broadcast-run! reach every live address
;;> space, by one multicast datagram when the lab says so, else each in
;;> turn; serve-group serves the calls that come by the group.

(define-library (murdoch delivery)
  (export broadcast-apply broadcast-run! serve-group)
  (import (scheme base) (srfi 1) (srfi 18)
          (chibi match)
          (murdoch scheduler) (murdoch log) (murdoch wait) (murdoch abandon)
          (murdoch remote-error) (murdoch frame) (murdoch lab) (murdoch sendable)
          (murdoch aspace) (murdoch connection)
          (murdoch call) (murdoch serve) (murdoch group))
  (include "delivery.scm"))
