;;> Delivery: broadcast-apply and broadcast-run! to every live address
;;> space, and serve-group for the calls that come by the group.

(define-library (murdoch remote delivery)
  (export broadcast-apply broadcast-run! serve-group)
  (import (scheme base) (srfi 1) (srfi 18) (murdoch sys) (murdoch code)
          (murdoch wire) (murdoch lab) (murdoch remote aspace)
          (murdoch remote connection) (murdoch remote call) (murdoch remote serve)
          (murdoch remote group))
  (include "delivery.scm"))
