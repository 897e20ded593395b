;;> The lab's multicast group: authentic datagrams that cannot be
;;> replayed, and beacons that keep the live set.  What a call means is
;;> left to the procedure start-group! is handed.

(define-library (murdoch group)
  (export start-group! delivery-mode send-datagram!)
  (import (scheme base) (scheme write) (srfi 18) (srfi 69)
          (only (chibi) call-with-output-string)
          (chibi net) (chibi match)
          (murdoch scheduler) (murdoch wait) (murdoch multicast)
          (murdoch frame) (murdoch lab) (murdoch aspace) (murdoch worker))
  (include "group.scm"))
